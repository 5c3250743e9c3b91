"""Action spaces (``jt.actions``): policy output ↔ PD targets."""

from __future__ import annotations

import abc
from typing import TYPE_CHECKING, Any

from toolkit.interfaces.plugin import Plugin

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np


class ActionSpace(Plugin, abc.ABC):
    """Maps a policy's action vector to PD targets, once per control step.

    Args:
        cfg: the ``action`` config group, validated against ``Config``.
        character: the character description the targets are for.
    """

    def __init__(self, cfg: Any, character: Any = None) -> None:
        self.cfg = cfg
        self.character = character

    @property
    @abc.abstractmethod
    def dim(self) -> int:
        """Size of the action vector."""

    @abc.abstractmethod
    def bounds(self) -> tuple["np.ndarray", "np.ndarray"]:
        """Lower and upper bounds ``(dim,)`` of the action vector."""

    @abc.abstractmethod
    def reset(self, state: Any = None) -> None:
        """Start of an episode (clears filters)."""

    @abc.abstractmethod
    def targets(self, action: "np.ndarray", obs: Any = None) -> "np.ndarray":
        """PD targets for the character's internal joints from ``action`` ``(dim,)``."""

    def penalty(self) -> float:
        """The action space's own reward term for the last step (1.0 = no penalty)."""
        return 1.0

    def anchor(self, q: "np.ndarray") -> None:
        """The episode's initial configuration ``(n_q,)``, given after every reset (for action
        spaces relative to it); ignored by default."""
