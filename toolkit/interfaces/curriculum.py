"""Curricula (``jt.curricula``): difficulty state updated from training statistics."""

from __future__ import annotations

import abc
from typing import Any

from toolkit.interfaces.plugin import Plugin


class Curriculum(Plugin, abc.ABC):
    """Holds a difficulty state and updates it from episode outcomes.

    Args:
        cfg: the ``curriculum`` config group, validated against ``Config``.
    """

    def __init__(self, cfg: Any = None) -> None:
        self.cfg = cfg

    @abc.abstractmethod
    def update(self, episode: dict[str, Any]) -> None:
        """Account for one finished episode's statistics."""

    @abc.abstractmethod
    def state(self) -> dict[str, float]:
        """Current difficulty values (saved in checkpoints, logged as metrics)."""

    @abc.abstractmethod
    def load_state(self, state: dict[str, float]) -> None:
        """Restore a saved ``state()``."""
