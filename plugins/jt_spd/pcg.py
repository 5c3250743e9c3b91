"""``spd=pcg``: Stable PD by Jacobi-preconditioned conjugate gradient (thesis 001 §2.4.2)."""

from __future__ import annotations

import dataclasses

from jt_spd.base import ToolkitSPD


class PCGBackend(ToolkitSPD):
    """Stable PD by Jacobi-preconditioned CG on M + Kd dt (thesis 001 §2.4.2)."""

    method = "pcg"

    @dataclasses.dataclass
    class Config:
        name: str = "pcg"
        """Registry name."""
        tol: float = 1e-12
        """Stop at ||b - A x|| <= tol ||b|| (true residual). Tighter stalls at round-off."""
        max_iter_factor: int = 20
        """Iteration cap = max_iter_factor * n_dof."""

        def check(self) -> None:
            """tol a finite number > 0, max_iter_factor >= 1 (one ``JtError`` line, at composition)."""
            from toolkit.schema import finite, require

            require(finite(self.tol) and self.tol > 0, "spd.tol", self.tol, "must be a finite number > 0")
            require(self.max_iter_factor >= 1, "spd.max_iter_factor", self.max_iter_factor, "must be >= 1")

    def _setup(self) -> None:
        self.tol = float(self.params.tol)
        self.max_iter_factor = int(self.params.max_iter_factor)

    def torques(self, q, qd, q_target, kp, kd, dt, qd_target=None, tau_ext=None):  # noqa: D102
        from toolkit.dynamics.spd import spd_system_kernel, _PCG

        if self.model is None:
            raise RuntimeError("SPD backend 'pcg': call bind(model) first")
        import numpy as np

        m, d = self.model, self.data
        c, f, z = np.ascontiguousarray, np.float64, d.zeros_v
        d.iterations = spd_system_kernel(
            m.mi, m.mf, m.dof_parent, c(q, f), c(qd, f), c(q_target, f),
            z if qd_target is None else c(qd_target, f), c(kp, f), c(kd, f), float(dt),
            z if tau_ext is None else c(tau_ext, f), m.gravity, d.wb, d.wv, d.sc, d.H, d.A, _PCG,
            self.tol, self.max_iter_factor * m.n_v)
        return d.tau

    def solve(self, q, qd, q_target, kp, kd, dt, qd_target=None):  # noqa: D102
        """``torques`` with this backend's ``tol`` and iteration cap (the simulator's per-substep path)."""
        return self.torques(q, qd, q_target, kp, kd, dt, qd_target)
