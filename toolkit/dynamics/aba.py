"""Articulated-body algorithm: forward dynamics ``qdd = M^-1 (tau - C)`` in O(n) (RBDA §7.3).

``articulated_body_kernel`` is written once for ABA and MABA: it solves

    (M + diag(K)) qdd = f - C

where ABA passes ``K = 0, f = tau`` and MABA (``toolkit.dynamics.maba``) passes the SPD terms
``K = Kd dt`` and ``f = Q`` (thesis eqs 2.19-2.20). The only places ``K`` appears are the two
lines the thesis modifies (eq 2.18 / 2.24-2.25):

    D_i = S_i^T I^A_i S_i + K_i          (ABA: D_i = S_i^T I^A_i S_i)
    u_i = f_i - S_i^T p^A_i              (ABA: u_i = tau_i - S_i^T p^A_i)

and everything downstream (``I^a``, ``p^a``, pass 3) uses ``D_i``, ``u_i`` as in ABA. A floating
base is a 6-DoF joint to the world with ``S_0 = [[0, E], [E, 0]]`` (world-frame ``[v; w]``), solved
with a 6x6 Cholesky at the root (same modification).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from toolkit.dynamics.kinematics import joint_transforms
from toolkit.dynamics.model import (JT_FREE, JT_REVOLUTE, JT_SPHERICAL, MF_AX, MF_IN, MI_JTYPE,
                                    MI_NV, MI_PARENT, MI_VI, W_A, W_C, W_DI, W_IA, W_PA, W_U,
                                    W_UV, W_V, W_XE, W_XR)
from toolkit.dynamics.rnea import base_velocity_terms
from toolkit.dynamics.spatial import (cross_force_add, cross_motion, mat6_vec, mat6_vec_add,
                                      xform_force_add, xform_inertia_add, xform_motion)

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.dynamics.model import Data, Model


@njit(cache=True, inline="always")
def _inv_sym3(D: np.ndarray, out: np.ndarray) -> None:
    """Inverse of a symmetric positive-definite 3x3 (row-major) by cofactors."""
    a, b, c, d, e, f = D[0], D[1], D[2], D[4], D[5], D[8]
    c0 = d * f - e * e
    c1 = c * e - b * f
    c2 = b * e - c * d
    inv = 1.0 / (a * c0 + b * c1 + c * c2)
    out[0] = c0 * inv
    out[1] = out[3] = c1 * inv
    out[2] = out[6] = c2 * inv
    out[4] = (a * f - c * c) * inv
    out[5] = out[7] = (b * c - a * e) * inv
    out[8] = (a * d - b * b) * inv


@njit(cache=True)
def chol_solve6(A: np.ndarray, b: np.ndarray, x: np.ndarray) -> None:
    """Solve the SPD 6x6 system ``A x = b`` (row-major ``A`` is overwritten by its factor)."""
    for j in range(6):
        s = A[7 * j]
        for k in range(j):
            s -= A[6 * j + k] * A[6 * j + k]
        A[7 * j] = math.sqrt(s)
        for i in range(j + 1, 6):
            s = A[6 * i + j]
            for k in range(j):
                s -= A[6 * i + k] * A[6 * j + k]
            A[6 * i + j] = s / A[7 * j]
    for i in range(6):
        s = b[i]
        for k in range(i):
            s -= A[6 * i + k] * x[k]
        x[i] = s / A[7 * i]
    for i in range(5, -1, -1):
        s = x[i]
        for k in range(i + 1, 6):
            s -= A[6 * k + i] * x[k]
        x[i] = s / A[7 * i]


@njit(cache=True)
def articulated_body_kernel(mi: np.ndarray, mf: np.ndarray, q: np.ndarray, qd: np.ndarray,
                            f_in: np.ndarray, K: np.ndarray, grav: np.ndarray, wb: np.ndarray,
                            sc: np.ndarray, qdd: np.ndarray) -> None:
    """Solve ``(M + diag(K)) qdd = f_in - C(q, qd)`` in three passes (see module docstring).

    Args:
        mi: packed integer model table.
        mf: packed float model table.
        q: positions ``(n_q,)``.
        qd: velocities ``(n_v,)``.
        f_in: generalised forces ``(n_v,)`` (ABA: ``tau``; MABA: ``Q``).
        K: non-negative diagonal added to ``M`` ``(n_v,)`` (ABA: zeros; MABA: ``Kd dt``).
        grav: gravity ``(3,)``.
        wb: per-body workspace.
        sc: scratch ``(>= 256,)``.
        qdd: output accelerations ``(n_v,)``.
    """
    nb = mi.shape[0]
    joint_transforms(mi, mf, q, wb, sc)
    vJ = sc[18:24]
    t6 = sc[24:30]
    ag = sc[30:36]
    UD = sc[36:54]
    # ---- pass 1: velocities, velocity products, single-body inertias and bias forces
    for i in range(nb):
        jt = mi[i, MI_JTYPE]
        vi = mi[i, MI_VI]
        E = wb[i, W_XE:W_XE + 9]
        v = wb[i, W_V:W_V + 6]
        c = wb[i, W_C:W_C + 6]
        if i == 0:
            base_velocity_terms(jt, E, qd, grav, v, c, ag)
        else:
            for k in range(6):
                vJ[k] = 0.0
            if jt == JT_SPHERICAL:
                vJ[0] = qd[vi]
                vJ[1] = qd[vi + 1]
                vJ[2] = qd[vi + 2]
            elif jt == JT_REVOLUTE:
                for k in range(3):
                    vJ[k] = mf[i, MF_AX + k] * qd[vi]
            else:
                for k in range(3):
                    vJ[3 + k] = mf[i, MF_AX + k] * qd[vi]
            xform_motion(E, wb[i, W_XR:W_XR + 3], wb[mi[i, MI_PARENT], W_V:W_V + 6], v)
            for k in range(6):
                v[k] += vJ[k]
            cross_motion(v, vJ, c)
        IA = wb[i, W_IA:W_IA + 36]
        for k in range(36):
            IA[k] = mf[i, MF_IN + k]
        pA = wb[i, W_PA:W_PA + 6]
        mat6_vec(IA, v, t6)
        for k in range(6):
            pA[k] = 0.0
        cross_force_add(v, t6, pA)
    # ---- pass 2: articulated-body inertias and bias forces, leaves to root
    for i in range(nb - 1, 0, -1):
        jt = mi[i, MI_JTYPE]
        vi = mi[i, MI_VI]
        d = mi[i, MI_NV]
        IA = wb[i, W_IA:W_IA + 36]
        pA = wb[i, W_PA:W_PA + 6]
        U = wb[i, W_U:W_U + 18]  # 6 x 3, row-major
        Di = wb[i, W_DI:W_DI + 9]
        u = wb[i, W_UV:W_UV + 3]
        c = wb[i, W_C:W_C + 6]
        if jt == JT_SPHERICAL:
            for a in range(6):
                for k in range(3):
                    U[3 * a + k] = IA[6 * a + k]
            for k in range(3):
                for l in range(3):
                    UD[3 * k + l] = U[3 * k + l]  # D = S^T U = U[0:3, :]
                UD[4 * k] += K[vi + k]  # <-- MABA: D_i = S^T I^A S + K_i  (eq 2.18)
                u[k] = f_in[vi + k] - pA[k]  # <-- MABA: u_i = Q_i - S^T p^A  (eq 2.18/2.20)
            _inv_sym3(UD[0:9], Di)
        else:
            off = 0 if jt == JT_REVOLUTE else 3
            ax0, ax1, ax2 = mf[i, MF_AX], mf[i, MF_AX + 1], mf[i, MF_AX + 2]
            for a in range(6):
                U[3 * a] = (IA[6 * a + off] * ax0 + IA[6 * a + off + 1] * ax1
                            + IA[6 * a + off + 2] * ax2)
            Dval = U[3 * off] * ax0 + U[3 * (off + 1)] * ax1 + U[3 * (off + 2)] * ax2
            Dval += K[vi]  # <-- MABA: D_i = S^T I^A S + K_i
            Di[0] = 1.0 / Dval
            u[0] = f_in[vi] - (pA[off] * ax0 + pA[off + 1] * ax1 + pA[off + 2] * ax2)  # <-- MABA
        # UD = U D^-1 (6 x d); I^a = I^A - UD U^T; p^a = p^A + I^a c + UD u
        for a in range(6):
            for k in range(d):
                s = 0.0
                for l in range(d):
                    s += U[3 * a + l] * Di[3 * l + k]
                UD[3 * a + k] = s
        for a in range(6):
            for b in range(a, 6):
                s = 0.0
                for k in range(d):
                    s += UD[3 * a + k] * U[3 * b + k]
                IA[6 * a + b] -= s
                if b > a:
                    IA[6 * b + a] -= s
        mat6_vec_add(IA, c, pA)
        for a in range(6):
            s = 0.0
            for k in range(d):
                s += UD[3 * a + k] * u[k]
            pA[a] += s
        p = mi[i, MI_PARENT]
        E = wb[i, W_XE:W_XE + 9]
        r = wb[i, W_XR:W_XR + 3]
        xform_inertia_add(E, r, IA, wb[p, W_IA:W_IA + 36], sc[64:128])
        xform_force_add(E, r, pA, wb[p, W_PA:W_PA + 6])
    # ---- root
    a0 = wb[0, W_A:W_A + 6]
    c0 = wb[0, W_C:W_C + 6]
    for k in range(6):
        a0[k] = ag[k] + c0[k]
    if mi[0, MI_JTYPE] == JT_FREE:
        E = wb[0, W_XE:W_XE + 9]
        IA = wb[0, W_IA:W_IA + 36]
        S = sc[128:164]
        T = sc[164:200]
        Dr = sc[200:236]
        w = sc[236:242]
        x = sc[242:248]
        for k in range(36):
            S[k] = 0.0
        for a in range(3):
            for b in range(3):
                S[6 * a + 3 + b] = E[3 * a + b]  # angular rows <- world w (cols 3..5)
                S[6 * (3 + a) + b] = E[3 * a + b]  # linear rows <- world v (cols 0..2)
        for a in range(6):
            for b in range(6):
                s = 0.0
                for k in range(6):
                    s += IA[6 * a + k] * S[6 * k + b]
                T[6 * a + b] = s
        for a in range(6):
            for b in range(6):
                s = 0.0
                for k in range(6):
                    s += S[6 * k + a] * T[6 * k + b]
                Dr[6 * a + b] = s
            Dr[7 * a] += K[a]  # <-- MABA at the root (hand-of-God gains; zero if unactuated)
        mat6_vec(IA, a0, w)
        for k in range(6):
            w[k] += wb[0, W_PA + k]
        for a in range(6):
            s = 0.0
            for k in range(6):
                s += S[6 * k + a] * w[k]
            t6[a] = f_in[a] - s  # <-- MABA: Q_0 instead of tau_0
        chol_solve6(Dr, t6, x)
        for a in range(6):
            qdd[a] = x[a]
            s = 0.0
            for k in range(6):
                s += S[6 * a + k] * x[k]
            a0[a] += s
    # ---- pass 3: accelerations, root to leaves
    for i in range(1, nb):
        jt = mi[i, MI_JTYPE]
        vi = mi[i, MI_VI]
        d = mi[i, MI_NV]
        a = wb[i, W_A:W_A + 6]
        xform_motion(wb[i, W_XE:W_XE + 9], wb[i, W_XR:W_XR + 3],
                     wb[mi[i, MI_PARENT], W_A:W_A + 6], a)
        for k in range(6):
            a[k] += wb[i, W_C + k]
        U = wb[i, W_U:W_U + 18]
        Di = wb[i, W_DI:W_DI + 9]
        u = wb[i, W_UV:W_UV + 3]
        for k in range(d):
            s = u[k]
            for b in range(6):
                s -= U[3 * b + k] * a[b]
            t6[k] = s
        if jt == JT_SPHERICAL:
            for k in range(3):
                qdd[vi + k] = Di[3 * k] * t6[0] + Di[3 * k + 1] * t6[1] + Di[3 * k + 2] * t6[2]
                a[k] += qdd[vi + k]
        else:
            qdd[vi] = Di[0] * t6[0]
            off = 0 if jt == JT_REVOLUTE else 3
            for k in range(3):
                a[off + k] += mf[i, MF_AX + k] * qdd[vi]


def aba(model: "Model", data: "Data", q: np.ndarray, qd: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """Forward dynamics: accelerations ``qdd`` ``(n_v,)`` under generalised forces ``tau``."""
    f = np.ascontiguousarray
    out = np.empty(model.n_v)
    articulated_body_kernel(model.mi, model.mf, f(q, dtype=np.float64), f(qd, dtype=np.float64),
                            f(tau, dtype=np.float64), data.zeros_v, model.gravity, data.wb,
                            data.sc, out)
    return out
