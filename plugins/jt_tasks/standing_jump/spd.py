"""Stable PD (Tan, Liu & Turk 2011) for the planar character, with PyBullet's dynamics.

Explicit PD at 1 kHz is unstable on this body: the pelvis (8.9 kg) and the neck link (0.8 kg)
are light hubs between stiffly damped joints, and the sum of their joints' damping exceeds what
an explicit step tolerates (``sum kd * dt / I > 2``). Stable PD evaluates the PD force at the
next step's state, which is unconditionally stable for any gains:

    qdd = (M + Kd dt)^-1 (-C - Kp (q + qd dt - q*) - Kd (qd - qd*) + tau_extra)
    tau = -Kp (q + qd dt - q*) - Kd (qd + qdd dt - qd*)

``M`` comes from ``pybullet.calculateMassMatrix`` and ``C`` (Coriolis, centrifugal and gravity
terms) from ``pybullet.calculateInverseDynamics`` with zero acceleration. The root's three joints
get zero gains, so their ``tau`` is zero. Ground contact is left out of the solve, as usual.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np


class StablePD:
    """SPD torques for one PyBullet body (fixed base, 1-DoF joints).

    Args:
        client: PyBullet client id.
        body: body id.
        n: number of joints (degrees of freedom).
        dt: time step (s).
    """

    def __init__(self, client: int, body: int, n: int, dt: float) -> None:
        import pybullet as p

        self._p = p
        self.client = client
        self.body = body
        self.n = n
        self.dt = dt
        self._zeros = [0.0] * n

    def torques(self, q: Sequence[float], qd: Sequence[float], target: np.ndarray, rate: np.ndarray,
                kp: np.ndarray, kd: np.ndarray, extra: Any = None) -> np.ndarray:
        """SPD torques ``(n,)`` for joint positions/rates ``q, qd`` and targets ``target, rate``.

        Args:
            q: joint positions ``(n,)``.
            qd: joint rates ``(n,)``.
            target: PD targets ``(n,)``.
            rate: target rates ``(n,)``.
            kp: stiffness ``(n,)``.
            kd: damping ``(n,)``.
            extra: torques applied besides the PD ``(n,)`` (they enter the acceleration estimate).
        """
        p, dt = self._p, self.dt
        q_list, qd_list = list(q), list(qd)
        M = np.asarray(p.calculateMassMatrix(self.body, q_list, physicsClientId=self.client))
        C = np.asarray(p.calculateInverseDynamics(self.body, q_list, qd_list, self._zeros,
                                                  physicsClientId=self.client))
        qa, qda = np.asarray(q_list), np.asarray(qd_list)
        pos_err = qa + qda * dt - target
        rhs = -C - kp * pos_err - kd * (qda - rate)
        if extra is not None:
            rhs = rhs + extra
        M[np.diag_indices(self.n)] += kd * dt
        qdd = np.linalg.solve(M, rhs)
        return -kp * pos_err - kd * (qda + qdd * dt - rate)
