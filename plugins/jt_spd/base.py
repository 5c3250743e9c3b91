"""Shared base of the ``toolkit.dynamics`` SPD backends (maba, df, sf, pcg)."""

from __future__ import annotations

from typing import Any, ClassVar

from toolkit.interfaces import SPDBackend


class ToolkitSPD(SPDBackend):
    """Stable PD by one of ``toolkit.dynamics.spd``'s solvers (subclasses pick ``method``).

    Usage by a simulator, per substep::

        backend.bind(model)                        # once (a toolkit.dynamics.Model or Character)
        tau = backend.torques(q, qd, q_target, kp, kd, dt)   # then clip, apply, stepSimulation

    or ``backend.control(io, ...)`` with the simulator's body I/O (``sim=bullet``'s ``BulletBody``) to read the
    state, solve, clip and apply in one call. ``torques`` returns an internal buffer that the next
    call overwrites (copy it to keep it).
    """

    method: ClassVar[str] = ""
    #: False: computes torques that the caller applies before ``stepSimulation``
    steps_itself: ClassVar[bool] = False

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        self.model: Any = None
        self.data: Any = None
        self._clip: Any = None

    def bind(self, body: Any) -> None:
        """Prepare for one body: a ``Model``, or anything with ``.model()`` (a ``Character``)."""
        import numpy as np

        from toolkit.dynamics.model import Data, Model

        model = body if isinstance(body, Model) else body.model()
        self.model = model
        self.data = Data(model)
        self._clip = np.empty(model.n_v)
        self._setup()

    def _setup(self) -> None:
        """Hook for subclasses (solver parameters from ``self.cfg``)."""

    def torques(self, q: Any, qd: Any, q_target: Any, kp: Any, kd: Any, dt: float,
                qd_target: Any = None, tau_ext: Any = None) -> Any:
        import numpy as np

        from toolkit.dynamics.spd import spd_solve

        if self.model is None:
            raise RuntimeError(f"SPD backend {self.method!r}: call bind(model) first")
        c, f = np.ascontiguousarray, np.float64  # no-ops for contiguous float64 arrays
        spd_solve(self.model, self.data, c(q, f), c(qd, f), c(q_target, f), c(kp, f), c(kd, f),
                  float(dt), self.method, None if qd_target is None else c(qd_target, f),
                  None if tau_ext is None else c(tau_ext, f))
        return self.data.tau

    def solve(self, q: Any, qd: Any, q_target: Any, kp: Any, kd: Any, dt: float,
              qd_target: Any = None) -> Any:
        """``torques`` for contiguous float64 arrays, without conversions (the simulator's
        per-substep path); returns ``data.tau`` ``(n_v,)``."""
        from toolkit.dynamics.spd import spd_solve

        spd_solve(self.model, self.data, q, qd, q_target, kp, kd, dt, self.method, qd_target)
        return self.data.tau

    def control(self, io: Any, q_target: Any, kp: Any, kd: Any, dt: float, torque_limit: Any,
                qd_target: Any = None) -> Any:
        """Read the state from ``io`` (a ``BulletBody``), solve, clip, apply; returns the torques.

        The caller then runs ``stepSimulation``.
        """
        import numpy as np

        q, qd = io.read()
        tau = self.torques(q, qd, q_target, kp, kd, dt, qd_target)
        np.clip(tau, -torque_limit, torque_limit, out=self._clip)
        io.write_torques(self._clip)
        return self._clip
