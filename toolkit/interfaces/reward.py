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
