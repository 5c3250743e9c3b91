"""``action=raw``: the policy outputs the PD targets themselves (exp maps and angles).

The "no pose VAE" baseline of ``000`` §7.2.2 (Fig. 10) and ``003`` §5 ("the get-up policy is
trained to directly produce PD servo target angles"). Bounds are the joint limits.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from jt_actions.base import DofActionSpace, FilterCheck


class RawActionSpace(DofActionSpace):
    """Action = PD targets (exp map per spherical joint, angle per revolute one), within limits."""

    @dataclasses.dataclass
    class Config(FilterCheck):
        name: str = "raw"
        beta: float = 1.0
        """Action filter y_t = beta a_t + (1 - beta) y_{t-1} (003 §3.4's, an option of every action
        space); 1: no filter (the papers' choice for this space)."""
        clip_to_limits: bool = True
        """Targets within the joint limits (URDF revolute ranges; |exp map| <= pi)."""
        around_start: bool = False
        """Actions are offsets from the episode's initial pose (target = start + a, exp maps
        added as 002 §4.2 adds corrections), so a policy's initial mean action (~0) holds the
        start pose: ours, for small budgets (docs/highjump.md); False: the targets themselves."""

    def __init__(self, cfg: Any = None, character: Any = None) -> None:
        super().__init__(cfg, character)
        self._start: np.ndarray | None = None

    @property
    def dim(self) -> int:
        return self.n_dof

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        low, high = self.joint_limits()
        if self.params.around_start:  # offsets: a full joint range either way
            span = high - low
            return -span, span.copy()
        return low.copy(), high.copy()

    def reset(self, state: Any = None) -> None:
        """New episode: the filter starts from zero (the raw space keeps no other state but its anchor)."""
        self.reset_filter(None)

    def anchor(self, q: np.ndarray) -> None:
        """Keep the initial pose's joint targets ``(n_dof,)`` (with ``around_start``)."""
        if self.params.around_start:
            self._start = self.skeleton.joints_to_dofs(np.asarray(q, dtype=np.float64)[7:])

    def targets(self, action: np.ndarray, obs: Any = None) -> np.ndarray:
        a = self.filter(action)
        if self.params.around_start:
            if self._start is None:
                raise RuntimeError("action=raw with around_start: anchor(q) is called after every reset")
            a = self._start + a
        return self.finish(a)
