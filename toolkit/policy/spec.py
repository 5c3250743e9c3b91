"""An env's spec derived from its task's ``Config``: every setting is declared once.

A policy task's env runs in rollout workers from a plain, picklable ``*Spec`` dataclass that
subclasses the task's ``Config``: it inherits every ``task.*`` setting (with its default and
source) and adds the values the task resolves from them (the sim and action groups, curves, bound
widths ...). ``spec_of`` copies the settings from the task's typed parameters, so a value the user
sets reaches the env through one mechanism, and adding a setting is one field in the ``Config``
(``tests/toolkit/policy/test_spec.py``).
"""

from __future__ import annotations

import copy
import dataclasses
from typing import Any


def shared_fields(spec_cls: type, config_cls: type) -> list[str]:
    """The field names ``spec_cls`` and ``config_cls`` both declare, in the spec's order."""
    names = {f.name for f in dataclasses.fields(config_cls)}
    return [f.name for f in dataclasses.fields(spec_cls) if f.name in names]


def spec_of(spec_cls: type, params: Any, **derived: Any) -> Any:
    """``spec_cls`` built from a task's typed ``params``: each field it shares by name with them is
    copied (containers deep-copied, so the spec stays plain data); ``derived`` gives the fields the
    task computes (a resolved heading axis, bound widths, the sim and action groups) and overrides
    a copy.

    Raises:
        TypeError: ``derived`` names a field ``spec_cls`` does not have.
    """
    names = {f.name for f in dataclasses.fields(spec_cls)}
    unknown = sorted(set(derived) - names)
    if unknown:
        raise TypeError(f"{spec_cls.__name__} has no field(s) {', '.join(unknown)}")
    values = {n: copy.deepcopy(getattr(params, n)) for n in shared_fields(spec_cls, type(params)) if n not in derived}
    return spec_cls(**values, **derived)
