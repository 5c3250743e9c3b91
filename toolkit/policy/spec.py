"""An env's spec derived from its task's ``Config``: every shared value is declared once.

A policy task's env runs in rollout workers from a plain, picklable ``*Spec`` dataclass. The
fields a spec shares by name with the task's ``Config`` are copied by ``spec_of`` — not by a hand
copy per field — and a spec declares a shared field's default as the ``Config``'s
(``default_of``), so a value the user sets in ``task.*`` reaches the env through one mechanism and
a default cannot differ between the two (``tests/toolkit/policy/test_spec.py``).
"""

from __future__ import annotations

import copy
import dataclasses
from typing import Any


def default_of(config_cls: type, name: str) -> Any:
    """A ``dataclasses.field`` with the default that ``config_cls`` declares for ``name``.

    Args:
        config_cls: a task's ``Config`` dataclass.
        name: one of its fields.
    """
    f = {f.name: f for f in dataclasses.fields(config_cls)}[name]
    if f.default_factory is not dataclasses.MISSING:
        return dataclasses.field(default_factory=f.default_factory)
    return dataclasses.field(default=f.default)


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
