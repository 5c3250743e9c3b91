"""A reward as the product of terms, each value kept for logging (``000`` eqs 2, 15, 16).

Toolkit-free: works with any callables ``term(record) -> float``. Tasks (plugins, which cannot
import this package) compose the same way through the registry::

    terms = {name: toolkit.plugins.load("reward", name)(params)
             for name, params in cfg.reward.terms.items()}
    values = {name: float(term(record)) for name, term in terms.items()}
    reward = math.prod(values.values())
"""

from __future__ import annotations

import math
from typing import Any, Callable, Iterable, Mapping, Union

Term = Callable[[dict[str, Any]], float]


def _named(terms: Union[Mapping[str, Term], Iterable[Term]]) -> list[tuple[str, Term]]:
    if isinstance(terms, Mapping):
        return [(str(k), t) for k, t in terms.items()]
    out = []
    for t in terms:
        name = getattr(type(t), "name", "") or getattr(t, "__name__", "") or type(t).__name__
        out.append((name, t))
    names = [n for n, _ in out]
    if len(set(names)) != len(names):
        raise ValueError(f"reward terms need distinct names, got {names}; pass a dict")
    return out


def product(terms: Union[Mapping[str, Term], Iterable[Term]],
            record: dict[str, Any]) -> tuple[float, dict[str, float]]:
    """The product of the terms' values on ``record``, and each value by name.

    Args:
        terms: ``{name: term}``, or terms named by their registry name (``type(term).name``) or
            function/class name.
        record: the task's step or episode record.

    Returns:
        ``(total, {name: value})``; every term is evaluated (even after a 0) so that each can
        be logged. An empty set of terms gives ``1.0``.
    """
    values = {name: float(term(record)) for name, term in _named(terms)}
    return math.prod(values.values()), values
