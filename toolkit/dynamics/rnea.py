"""Recursive Newton-Euler inverse dynamics (Featherstone RBDA §5.3); bias ``C = rnea(q, qd, 0)``.

``tau = M(q) qdd + C(q, qd)`` where ``C`` holds Coriolis, centrifugal and gravity terms. Gravity
enters as a fictitious base acceleration ``-g`` (so the ``a_i`` computed are "apparent").
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from toolkit.dynamics.kinematics import joint_transforms
from toolkit.dynamics.model import (JT_FREE, JT_REVOLUTE, JT_SPHERICAL, MF_AX, MF_IN, MI_JTYPE,
                                    MI_PARENT, MI_VI, V_BIAS, W_A, W_C, W_F, W_V, W_XE, W_XR)
from toolkit.dynamics.spatial import (cross_force_add, cross_motion, mat6_vec, xform_force_add,
                                      xform_motion)

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.dynamics.model import Data, Model


@njit(cache=True)
def base_velocity_terms(jt: int, E: np.ndarray, qd: np.ndarray, grav: np.ndarray,
                        v: np.ndarray, c: np.ndarray, ag: np.ndarray) -> None:
    """Base spatial velocity ``v``, velocity-product ``c`` and gravity acceleration ``ag``.

    All in base coordinates: ``v = S_0 qd_0``, ``c = [0; -(E w) x (E v)]`` (zero for a fixed base),
    ``ag = [0; -E g]``.
    """
    for a in range(6):
        v[a] = 0.0
        c[a] = 0.0
    ag[0] = ag[1] = ag[2] = 0.0
    for a in range(3):
        ag[3 + a] = -(E[3 * a] * grav[0] + E[3 * a + 1] * grav[1] + E[3 * a + 2] * grav[2])
    if jt == JT_FREE:
        for a in range(3):
            v[a] = E[3 * a] * qd[3] + E[3 * a + 1] * qd[4] + E[3 * a + 2] * qd[5]
            v[3 + a] = E[3 * a] * qd[0] + E[3 * a + 1] * qd[1] + E[3 * a + 2] * qd[2]
        c[3] = -(v[1] * v[5] - v[2] * v[4])
        c[4] = -(v[2] * v[3] - v[0] * v[5])
        c[5] = -(v[0] * v[4] - v[1] * v[3])


@njit(cache=True)
def rnea_kernel(mi: np.ndarray, mf: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                grav: np.ndarray, wb: np.ndarray, sc: np.ndarray, tau: np.ndarray) -> None:
    """Inverse dynamics into ``tau`` ``(n_v,)`` (see module docstring)."""
    nb = mi.shape[0]
    joint_transforms(mi, mf, q, wb, sc)
    vJ = sc[18:24]
    t6 = sc[24:30]
    ag = sc[30:36]
    for i in range(nb):
        jt = mi[i, MI_JTYPE]
        vi = mi[i, MI_VI]
        E = wb[i, W_XE:W_XE + 9]
        r = wb[i, W_XR:W_XR + 3]
        v = wb[i, W_V:W_V + 6]
        a = wb[i, W_A:W_A + 6]
        if i == 0:
            c = wb[i, W_C:W_C + 6]
            base_velocity_terms(jt, E, qd, grav, v, c, ag)
            for k in range(6):
                a[k] = ag[k] + c[k]
            if jt == JT_FREE:
                for k in range(3):
                    a[k] += E[3 * k] * qdd[3] + E[3 * k + 1] * qdd[4] + E[3 * k + 2] * qdd[5]
                    a[3 + k] += E[3 * k] * qdd[0] + E[3 * k + 1] * qdd[1] + E[3 * k + 2] * qdd[2]
        else:
            p = mi[i, MI_PARENT]
            for k in range(6):
                vJ[k] = 0.0
                t6[k] = 0.0
            if jt == JT_SPHERICAL:
                for k in range(3):
                    vJ[k] = qd[vi + k]
                    t6[k] = qdd[vi + k]
            elif jt == JT_REVOLUTE:
                for k in range(3):
                    vJ[k] = mf[i, MF_AX + k] * qd[vi]
                    t6[k] = mf[i, MF_AX + k] * qdd[vi]
            else:
                for k in range(3):
                    vJ[3 + k] = mf[i, MF_AX + k] * qd[vi]
                    t6[3 + k] = mf[i, MF_AX + k] * qdd[vi]
            xform_motion(E, r, wb[p, W_V:W_V + 6], v)
            for k in range(6):
                v[k] += vJ[k]
            xform_motion(E, r, wb[p, W_A:W_A + 6], a)
            for k in range(6):
                a[k] += t6[k]
            cross_motion(v, vJ, t6)
            for k in range(6):
                a[k] += t6[k]
        # f = I a + v x* I v
        f = wb[i, W_F:W_F + 6]
        I = mf[i, MF_IN:MF_IN + 36]
        mat6_vec(I, a, f)
        mat6_vec(I, v, t6)
        cross_force_add(v, t6, f)
    for i in range(nb - 1, -1, -1):
        jt = mi[i, MI_JTYPE]
        vi = mi[i, MI_VI]
        f = wb[i, W_F:W_F + 6]
        E = wb[i, W_XE:W_XE + 9]
        if i == 0:
            if jt == JT_FREE:
                for k in range(3):
                    tau[k] = E[k] * f[3] + E[3 + k] * f[4] + E[6 + k] * f[5]
                    tau[3 + k] = E[k] * f[0] + E[3 + k] * f[1] + E[6 + k] * f[2]
            continue
        if jt == JT_SPHERICAL:
            tau[vi] = f[0]
            tau[vi + 1] = f[1]
            tau[vi + 2] = f[2]
        elif jt == JT_REVOLUTE:
            tau[vi] = mf[i, MF_AX] * f[0] + mf[i, MF_AX + 1] * f[1] + mf[i, MF_AX + 2] * f[2]
        else:
            tau[vi] = mf[i, MF_AX] * f[3] + mf[i, MF_AX + 1] * f[4] + mf[i, MF_AX + 2] * f[5]
        xform_force_add(E, wb[i, W_XR:W_XR + 3], f, wb[mi[i, MI_PARENT], W_F:W_F + 6])


def rnea(model: "Model", data: "Data", q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
         gravity: bool = True) -> np.ndarray:
    """Generalised forces ``tau`` ``(n_v,)`` that produce ``qdd`` at ``(q, qd)``.

    Args:
        model: the articulated body.
        data: its workspace.
        q: positions ``(n_q,)``.
        qd: velocities ``(n_v,)``.
        qdd: accelerations ``(n_v,)``.
        gravity: include ``model.gravity``.

    Returns:
        ``tau`` (a new array).
    """
    g = model.gravity if gravity else np.zeros(3)
    out = np.empty(model.n_v)
    rnea_kernel(model.mi, model.mf, _f(q), _f(qd), _f(qdd), g, data.wb, data.sc, out)
    return out


def bias(model: "Model", data: "Data", q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """Bias forces ``C(q, qd) = rnea(q, qd, 0)`` ``(n_v,)`` (Coriolis, centrifugal, gravity)."""
    rnea_kernel(model.mi, model.mf, _f(q), _f(qd), data.zeros_v, model.gravity, data.wb, data.sc,
                data.wv[V_BIAS])
    return data.wv[V_BIAS].copy()


def _f(x: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(x, dtype=np.float64)
