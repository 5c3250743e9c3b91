"""Reward terms (``jt.rewards``): a task's reward is the product of its terms (``000`` eq 2)."""

from __future__ import annotations

import abc
from typing import Any, ClassVar

from toolkit.interfaces.plugin import GroupPlugin


class RewardTerm(GroupPlugin, abc.ABC):
    """A scalar factor computed from a step (or episode) record.

    Args:
        cfg: this term's parameters, validated against ``Config``.
    """

    what: ClassVar[str] = "reward term {name}"

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)

    @abc.abstractmethod
    def __call__(self, record: dict[str, Any]) -> float:
        """The term's value for ``record`` (a task's step or episode record)."""

    #: record keys the term reads only when present (``record.get``): not checked at composition
    optional_keys: ClassVar[tuple[str, ...]] = ()

    @classmethod
    def needs(cls, params: Any) -> set[str]:
        """The record keys this term reads with ``params`` (its group node or ``Config``): by
        default the values of its fields named ``key`` / ``keys`` or ending in ``_key`` / ``_keys``
        but those in ``optional_keys``. Composition checks them against the task's declared
        ``Task.record_keys``; a term that reads other keys overrides this."""
        out: set[str] = set()
        items = params.items() if hasattr(params, "items") else vars(params).items()
        for name, value in items:
            name = str(name)
            if name in cls.optional_keys or not (name in ("key", "keys") or name.endswith(("_key", "_keys"))):
                continue
            values = [value] if isinstance(value, str) or not hasattr(value, "__iter__") else list(value)
            out.update(str(v) for v in values if v is not None and str(v))
        return out
