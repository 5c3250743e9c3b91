"""``task.max_time_to_bar``: the high-jump take-off states whose run-up reaches the bar plane in flight.

A take-off state fixes the root's horizontal velocity ``(v_x, v_z)`` in the facing frame (``v_x``
from the run clip, ``v_z`` a searched feature) and the approach angle ``alpha`` fixes the bar's
normal ``n = (sin alpha, -cos alpha)`` (``000`` App. A; ``jt_tasks.jumping.scene``). The speed
towards the bar plane is

    v_n = v_x sin(alpha) - v_z cos(alpha)

and the root, ``distance`` before the plane, needs ``distance / v_n`` to reach it. In flight the
CoM's horizontal velocity cannot change, so a state with a small ``v_n`` runs along the bar and
comes down before it crosses: no policy gives it a feature. ``BarReach`` is that known constraint,
``margin = v_n - distance / t_max >= 0``, for the searchers (``SearchProblem.constraint``). Ours:
``000`` gives no search box; docs/journal/jumping.md has the measurements behind it.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Optional

import numpy as np


@dataclasses.dataclass(frozen=True)
class BarReach:
    """Margins ``v_n - distance / t_max`` (m/s) of take-off feature points.

    Attributes:
        names: the searched features, in the order of a point's columns.
        v_x: forward root speed of the take-off state (m/s, facing frame).
        alpha: the approach angle when it is not searched (rad).
        v_z: the sideways root speed when it is not searched (m/s, facing frame).
        distance: take-off root to the bar plane (m, ``task.distance``).
        t_max: the longest time to the plane (s, ``task.max_time_to_bar``).
    """

    names: tuple[str, ...]
    v_x: float
    alpha: Optional[float]
    v_z: Optional[float]
    distance: float
    t_max: float

    @classmethod
    def of_task(cls, task: Any, names: list[str], t_max: float) -> "BarReach":
        """The constraint of a high-jump task.

        Args:
            task: the ``HighJumpTask`` (its params, fixed features and take-off file).
            names: its searched features, in the order of a point's columns.
            t_max: ``task.max_time_to_bar`` (s).

        Returns:
            The constraint, with the take-off state's forward speed.
        """
        from jt_tasks.takeoff.state import facing_velocities, takeoff_state

        p = task.params
        feats = {**(p.takeoff or {}), **{k: float(v) for k, v in task._fixed().items()}}
        if task.takeoff_file() is not None:
            from jt_tasks.takeoff import source as takeoff_source

            state = takeoff_source.load(task.takeoff_file(), p.foot, p.v_y)
        else:
            state = takeoff_state({k: float(v) for k, v in feats.items() if k != "alpha"}, p.clip, p.foot,
                                  p.omega_y, v_y=p.v_y)
        v_f, _ = facing_velocities(state.q, state.qd)
        return cls(names=tuple(names), v_x=float(v_f[0]),
                   alpha=None if "alpha" in names else float(feats.get("alpha", 0.0)),
                   v_z=None if "v_z" in names else float(feats.get("v_z", v_f[2])),
                   distance=float(p.distance), t_max=float(t_max))

    def speed(self, X: np.ndarray) -> np.ndarray:
        """``v_n`` (m/s) at feature points ``X`` ``(n, len(names))`` → ``(n,)``."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        alpha = X[:, self.names.index("alpha")] if self.alpha is None else np.full(len(X), self.alpha)
        v_z = X[:, self.names.index("v_z")] if self.v_z is None else np.full(len(X), self.v_z)
        return self.v_x * np.sin(alpha) - v_z * np.cos(alpha)

    @property
    def min_speed(self) -> float:
        """The slowest ``v_n`` allowed (m/s)."""
        return self.distance / self.t_max

    def __call__(self, X: np.ndarray) -> np.ndarray:
        """Margins ``v_n - distance / t_max`` (m/s) ``(n,)``: feasible where ``>= 0``."""
        return self.speed(X) - self.min_speed

    def time_to_bar(self, X: np.ndarray) -> np.ndarray:
        """``distance / v_n`` (s) ``(n,)``; inf where the run-up does not head towards the bar."""
        v = self.speed(X)
        return np.where(v > 0, self.distance / np.where(v > 0, v, 1.0), math.inf)
