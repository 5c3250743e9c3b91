"""``action=raw``: the policy outputs the PD targets themselves (exp maps and angles).

The "no pose VAE" baseline of ``000`` §7.2.2 (Fig. 10) and ``003`` §5 ("the get-up policy is
trained to directly produce PD servo target angles"). Bounds are the joint limits.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from jt_actions.base import DofActionSpace


class RawActionSpace(DofActionSpace):
    """Action = PD targets (exp map per spherical joint, angle per revolute one), within limits."""

    @dataclasses.dataclass
    class Config:
        name: str = "raw"
        clip_to_limits: bool = True
        """Targets within the joint limits (URDF revolute ranges; |exp map| <= pi)."""

    @property
    def dim(self) -> int:
        return self.n_dof

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        low, high = self.joint_limits()
        return low.copy(), high.copy()

    def reset(self, state: Any = None) -> None:
        """Nothing to clear: the raw space keeps no state."""

    def targets(self, action: np.ndarray, obs: Any = None) -> np.ndarray:
        return self.finish(self.check_action(action))
