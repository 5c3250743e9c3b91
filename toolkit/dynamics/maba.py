"""Modified articulated-body algorithm: Stable PD in O(n) (thesis ``001`` §2.3, eqs 2.12-2.29).

SPD (eq 2.6) asks for torques computed from the state one step ahead,

    tau = -Kp (q + dt qd - q_target) - Kd (qd + dt qdd - qd_target),

with ``qdd`` the resulting acceleration. Writing ``K = Kd dt`` (eq 2.19) and
``Q = -Kp (q + dt qd - q_target) - Kd (qd - qd_target)`` (eq 2.20, here with a target velocity),
``tau = Q - K qdd`` and the equation of motion ``M qdd = tau - C`` become

    (M + K) qdd = Q - C                                   (eq 2.7)

MABA solves this with ABA's three passes, replacing ``tau_i`` by ``Q_i`` and adding ``K_i`` to
``D_i = S_i^T I^A_i S_i`` (eqs 2.18, 2.24, 2.25); see ``toolkit.dynamics.aba`` for the two
modified lines. The torques are then ``tau = Q - K qdd`` (eq 2.17) at O(n) extra cost.

Position errors on the manifold (as DeepMimic and PyBullet's ``STABLE_PD_CONTROL``): the pose is
first predicted one step ahead, then compared with the target through the log map:
    * revolute / prismatic: ``e = q_target - (q + dt qd)``;
    * spherical (child-frame angular velocity ``w``):
      ``e = log(conj(q exp(dt w)) q_target)`` in child coordinates;
    * floating base (only with root gains, the thesis' "hand-of-God" servo, §2.4.1):
      ``e_lin = p_target - (p + dt v)``, ``e_ang = log(q_target conj(exp(dt w) q))`` (world frame).
A DoF with ``kp = 0`` ignores its target (so an unactuated root may carry any target values).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from toolkit.dynamics.aba import articulated_body_kernel
from toolkit.dynamics.model import (JT_FREE, JT_SPHERICAL, MI_JTYPE, MI_QI, MI_VI, V_K, V_Q,
                                    V_QDD, V_RHS, V_TAU)
from toolkit.dynamics.spatial import quat_exp, quat_log, quat_mul

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.dynamics.model import Data, Model


@njit(cache=True)
def spd_terms_kernel(mi: np.ndarray, q: np.ndarray, qd: np.ndarray, qt: np.ndarray,
                     qdt: np.ndarray, kp: np.ndarray, kd: np.ndarray, dt: float, Q: np.ndarray,
                     K: np.ndarray) -> None:
    """SPD terms ``Q`` (eq 2.20) and ``K = Kd dt`` (eq 2.19), both ``(n_v,)``."""
    nb = mi.shape[0]
    for i in range(nb):
        jt = mi[i, MI_JTYPE]
        qi = mi[i, MI_QI]
        vi = mi[i, MI_VI]
        if jt == JT_FREE:
            for k in range(3):
                Q[k] = 0.0
                if kp[k] != 0.0:
                    Q[k] = kp[k] * (qt[qi + k] - q[qi + k] - dt * qd[k])
            x, y, z, w = q[qi + 3], q[qi + 4], q[qi + 5], q[qi + 6]
            ex, ey, ez, ew = quat_exp(dt * qd[3], dt * qd[4], dt * qd[5])
            px, py, pz, pw = quat_mul(ex, ey, ez, ew, x, y, z, w)  # predicted (world w)
            dx, dy, dz, dw = quat_mul(qt[qi + 3], qt[qi + 4], qt[qi + 5], qt[qi + 6],
                                      -px, -py, -pz, pw)
            e0, e1, e2 = quat_log(dx, dy, dz, dw)
            Q[3] = kp[3] * e0 if kp[3] != 0.0 else 0.0
            Q[4] = kp[4] * e1 if kp[4] != 0.0 else 0.0
            Q[5] = kp[5] * e2 if kp[5] != 0.0 else 0.0
            for k in range(6):
                if kd[k] != 0.0:
                    Q[k] += kd[k] * (qdt[k] - qd[k])
        elif jt == JT_SPHERICAL:
            x, y, z, w = q[qi], q[qi + 1], q[qi + 2], q[qi + 3]
            ex, ey, ez, ew = quat_exp(dt * qd[vi], dt * qd[vi + 1], dt * qd[vi + 2])
            px, py, pz, pw = quat_mul(x, y, z, w, ex, ey, ez, ew)  # predicted (local w)
            dx, dy, dz, dw = quat_mul(-px, -py, -pz, pw, qt[qi], qt[qi + 1], qt[qi + 2],
                                      qt[qi + 3])
            e0, e1, e2 = quat_log(dx, dy, dz, dw)
            Q[vi] = kp[vi] * e0 if kp[vi] != 0.0 else 0.0
            Q[vi + 1] = kp[vi + 1] * e1 if kp[vi + 1] != 0.0 else 0.0
            Q[vi + 2] = kp[vi + 2] * e2 if kp[vi + 2] != 0.0 else 0.0
            for k in range(3):
                if kd[vi + k] != 0.0:
                    Q[vi + k] += kd[vi + k] * (qdt[vi + k] - qd[vi + k])
        elif i > 0:
            Q[vi] = 0.0
            if kp[vi] != 0.0:
                Q[vi] = kp[vi] * (qt[qi] - q[qi] - dt * qd[vi])
            if kd[vi] != 0.0:
                Q[vi] += kd[vi] * (qdt[vi] - qd[vi])
    for k in range(K.shape[0]):
        K[k] = kd[k] * dt


@njit(cache=True)
def maba_kernel(mi: np.ndarray, mf: np.ndarray, q: np.ndarray, qd: np.ndarray, qt: np.ndarray,
                qdt: np.ndarray, kp: np.ndarray, kd: np.ndarray, dt: float, tau_ext: np.ndarray,
                grav: np.ndarray, wb: np.ndarray, wv: np.ndarray, sc: np.ndarray) -> None:
    """SPD by MABA: accelerations into ``wv[V_QDD]``, torques ``Q - K qdd`` into ``wv[V_TAU]``."""
    Q = wv[V_Q]
    K = wv[V_K]
    f = wv[V_RHS]
    spd_terms_kernel(mi, q, qd, qt, qdt, kp, kd, dt, Q, K)
    for k in range(Q.shape[0]):
        f[k] = Q[k] + tau_ext[k]
    qdd = wv[V_QDD]
    articulated_body_kernel(mi, mf, q, qd, f, K, grav, wb, sc, qdd)
    tau = wv[V_TAU]
    for k in range(Q.shape[0]):
        tau[k] = Q[k] - K[k] * qdd[k]


def maba(model: "Model", data: "Data", q: np.ndarray, qd: np.ndarray, q_target: np.ndarray,
         kp: np.ndarray, kd: np.ndarray, dt: float, qd_target: np.ndarray | None = None,
         tau_ext: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """SPD torques and the accelerations they produce, in O(n).

    Args:
        model: the articulated body.
        data: its workspace.
        q: positions ``(n_q,)``.
        qd: velocities ``(n_v,)``.
        q_target: target positions for the next step ``(n_q,)``.
        kp: stiffness per DoF ``(n_v,)``.
        kd: damping per DoF ``(n_v,)``.
        dt: time step in seconds.
        qd_target: target velocities ``(n_v,)`` (zero if None).
        tau_ext: other generalised forces acting this step ``(n_v,)`` (zero if None).

    Returns:
        ``(tau, qdd)``, each ``(n_v,)``: ``qdd`` solves ``(M + Kd dt) qdd = Q + tau_ext - C``.
    """
    c = np.ascontiguousarray
    z = data.zeros_v
    maba_kernel(model.mi, model.mf, c(q, dtype=np.float64), c(qd, dtype=np.float64),
                c(q_target, dtype=np.float64),
                z if qd_target is None else c(qd_target, dtype=np.float64),
                c(kp, dtype=np.float64), c(kd, dtype=np.float64), float(dt),
                z if tau_ext is None else c(tau_ext, dtype=np.float64), model.gravity, data.wb,
                data.wv, data.sc)
    return data.wv[V_TAU].copy(), data.wv[V_QDD].copy()
