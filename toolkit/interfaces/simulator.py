"""Simulators (``jt.simulators``): a character in a scene, stepped at the simulation rate."""

from __future__ import annotations

import abc
from typing import TYPE_CHECKING, Any

from toolkit.interfaces.plugin import Plugin

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np


class Simulator(Plugin, abc.ABC):
    """A physics world holding one controlled character and its scene.

    Control happens at ``control_hz``; each control step runs ``sim_hz / control_hz`` simulation
    substeps, each computing SPD torques with the configured backend. A NaN or exploding state
    ends the episode as a failure with a reason; it never raises.

    Args:
        cfg: the whole run config (``cfg.sim``, ``cfg.character``, ``cfg.spd``).
    """

    def __init__(self, cfg: Any) -> None:
        self.cfg = cfg

    @abc.abstractmethod
    def reset(self, q: "np.ndarray", qd: "np.ndarray") -> None:
        """Put the character in state ``(q, qd)``."""

    @abc.abstractmethod
    def step(self, q_target: "np.ndarray") -> dict[str, Any]:
        """One control step towards ``q_target``; returns a step record (state, contacts, failure)."""

    @abc.abstractmethod
    def state(self) -> tuple["np.ndarray", "np.ndarray"]:
        """Current ``(q, qd)``."""

    def render(self, width: int = 320, height: int = 240) -> "np.ndarray":
        """RGB frame ``(height, width, 3)`` uint8, headless."""
        raise NotImplementedError

    def close(self) -> None:
        """Release the physics world."""
