"""Stable PD torques for any articulated body: the public API of ``toolkit.dynamics``.

Four methods solve the same SPD system (thesis eq 2.7, see ``toolkit.dynamics.maba``)

    (M + Kd dt) qdd = Q + tau_ext - C,      tau = Q - Kd dt qdd

* ``"maba"``: the modified articulated-body algorithm, O(n) (thesis §2.3);
* ``"df"``: ``M`` by CRBA, ``C`` by RNEA, dense Cholesky of ``M + Kd dt`` (O(n^3), §2.2.3);
* ``"sf"``: the same system with Featherstone's sparse ``L^T L`` factorisation (O(n d^2));
* ``"pcg"``: the same system by Jacobi-preconditioned conjugate gradient.

Example::

    from toolkit.dynamics import Data, spd_torques

    model = character.model()                        # once (a simulator plugin builds it)
    data = Data(model)                               # once per thread
    tau = spd_torques(model, data, q, qd, q_target, kp, kd, dt=1 / 600)

Torque limits are applied after the solve (``torque_limit``), as DeepMimic and PyBullet do.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from toolkit.dynamics.crba import crba_kernel
from toolkit.dynamics.dense import chol_factor, chol_solve
from toolkit.dynamics.maba import maba_kernel, spd_terms_kernel
from toolkit.dynamics.model import (V_AP, V_BIAS, V_K, V_P, V_PRE, V_Q, V_QDD, V_R, V_RHS, V_TAU,
                                    V_Z)
from toolkit.dynamics.pcg import pcg_solve
from toolkit.dynamics.rnea import rnea_kernel
from toolkit.dynamics.sparse_ltl import ltl_factor, ltl_solve

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.dynamics.model import Data, Model

METHODS = ("maba", "df", "sf", "pcg")
_DF, _SF, _PCG = 0, 1, 2
PCG_TOL = 1e-12  #: relative residual at which PCG stops (tighter stalls at round-off on the snakes)
PCG_MAX_ITER_FACTOR = 20  #: PCG iteration cap = factor * n_v


@njit(cache=True)
def spd_system_kernel(mi: np.ndarray, mf: np.ndarray, lam: np.ndarray, q: np.ndarray,
                      qd: np.ndarray, qt: np.ndarray, qdt: np.ndarray, kp: np.ndarray,
                      kd: np.ndarray, dt: float, tau_ext: np.ndarray, grav: np.ndarray,
                      wb: np.ndarray, wv: np.ndarray, sc: np.ndarray, H: np.ndarray,
                      A: np.ndarray, mode: int, tol: float, max_iter: int) -> int:
    """SPD by forming ``M + Kd dt`` explicitly and solving by DF (0), SF (1) or PCG (2).

    Results go to ``wv[V_QDD]`` and ``wv[V_TAU]``; returns the PCG iteration count (else 0).
    """
    Q = wv[V_Q]
    K = wv[V_K]
    spd_terms_kernel(mi, q, qd, qt, qdt, kp, kd, dt, Q, K)
    crba_kernel(mi, mf, q, wb, sc, H)
    C = wv[V_BIAS]
    zero = wv[V_AP]
    n = Q.shape[0]
    for k in range(n):
        zero[k] = 0.0
    rnea_kernel(mi, mf, q, qd, zero, grav, wb, sc, C)
    b = wv[V_RHS]
    for k in range(n):
        b[k] = Q[k] + tau_ext[k] - C[k]
    if mode == _SF:  # only ancestor entries (lower triangle) are read and written
        for i in range(n):
            A[i, i] = H[i, i] + K[i]
            j = lam[i]
            while j != -1:
                A[i, j] = H[i, j]
                j = lam[j]
    else:
        for i in range(n):
            for j in range(n):
                A[i, j] = H[i, j]
            A[i, i] += K[i]
    qdd = wv[V_QDD]
    its = 0
    if mode == _DF:
        chol_factor(A)
        chol_solve(A, b, qdd)
    elif mode == _SF:
        ltl_factor(A, lam)
        ltl_solve(A, lam, b, qdd)
    else:
        its = pcg_solve(A, b, qdd, wv[V_R], wv[V_Z], wv[V_P], wv[V_AP], wv[V_PRE], tol, max_iter)
    tau = wv[V_TAU]
    for k in range(n):
        tau[k] = Q[k] - K[k] * qdd[k]
    return its


def spd_solve(model: "Model", data: "Data", q: np.ndarray, qd: np.ndarray, q_target: np.ndarray,
              kp: np.ndarray, kd: np.ndarray, dt: float, method: str = "maba",
              qd_target: np.ndarray | None = None, tau_ext: np.ndarray | None = None) -> None:
    """Solve SPD into ``data.tau`` and ``data.qdd`` without copying (the lean path).

    All arrays must be contiguous float64 (no conversion is done here). Arguments as in
    ``spd_torques``.
    """
    z = data.zeros_v
    qdt = z if qd_target is None else qd_target
    te = z if tau_ext is None else tau_ext
    if method == "maba":
        maba_kernel(model.mi, model.mf, q, qd, q_target, qdt, kp, kd, dt, te, model.gravity,
                    data.wb, data.wv, data.sc)
        return
    mode = {"df": _DF, "sf": _SF, "pcg": _PCG}.get(method)
    if mode is None:
        raise ValueError(f"unknown SPD method {method!r}; expected one of {METHODS}")
    data.iterations = spd_system_kernel(model.mi, model.mf, model.dof_parent, q, qd, q_target,
                                        qdt, kp, kd, dt, te, model.gravity, data.wb, data.wv,
                                        data.sc, data.H, data.A, mode, PCG_TOL,
                                        PCG_MAX_ITER_FACTOR * model.n_v)


def spd_torques(model: "Model", data: "Data", q: np.ndarray, qd: np.ndarray,
                q_target: np.ndarray, kp: np.ndarray, kd: np.ndarray, dt: float,
                method: str = "maba", qd_target: np.ndarray | None = None,
                tau_ext: np.ndarray | None = None,
                torque_limit: np.ndarray | None = None) -> np.ndarray:
    """Stable PD generalised forces for targets one step ahead (thesis eq 2.4 / 2.6).

    Args:
        model: the articulated body (a ``Model``).
        data: its workspace (``Data(model)``).
        q: positions ``(n_q,)``.
        qd: velocities ``(n_v,)``.
        q_target: target positions ``(n_q,)``; spherical targets are quaternions, errors use the
            log map. Entries of DoFs with ``kp = 0`` (e.g. an unactuated root) are ignored.
        kp: stiffness per DoF ``(n_v,)``; zeros on the 6 root DoFs leave the root unactuated,
            non-zero values make it a "hand-of-God" servo (thesis §2.4.1).
        kd: damping per DoF ``(n_v,)``.
        dt: time step in seconds.
        method: ``"maba"``, ``"df"``, ``"sf"`` or ``"pcg"`` (same result to ~1e-10).
        qd_target: target velocities ``(n_v,)``, zero if None.
        tau_ext: other known generalised forces this step ``(n_v,)`` (enter the dynamics, not
            the returned torques), zero if None.
        torque_limit: symmetric clip applied after the solve ``(n_v,)``; None for no limit.

    Returns:
        Generalised forces ``(n_v,)`` (a new array). ``data.qdd`` holds the accelerations the
        unclipped torques produce.
    """
    c = np.ascontiguousarray
    f64 = np.float64
    spd_solve(model, data, c(q, dtype=f64), c(qd, dtype=f64), c(q_target, dtype=f64),
              c(kp, dtype=f64), c(kd, dtype=f64), float(dt), method,
              None if qd_target is None else c(qd_target, dtype=f64),
              None if tau_ext is None else c(tau_ext, dtype=f64))
    tau = data.wv[V_TAU].copy()
    if torque_limit is not None:
        np.clip(tau, -torque_limit, torque_limit, out=tau)
    return tau
