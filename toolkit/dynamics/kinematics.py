"""Joint transforms and motion subspaces shared by every algorithm (numba kernels).

``joint_transforms`` fills ``wb[i, W_XE:W_XR+3]`` with ``X_i`` (parent body -> body ``i``; for
body 0, world -> base). Motion subspaces ``S_i`` are constant in body coordinates for revolute
(``[axis; 0]``), prismatic (``[0; axis]``) and spherical (``[I; 0]``, local angular velocity)
joints. The floating base uses world-frame velocities ``[v; w]``, so in base coordinates
``S_0 = [[0, E], [E, 0]]`` with ``E = R^T`` and its velocity-product term is
``c_0 = [0; -(E w) x (E v)]``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from toolkit.dynamics.model import (JT_FIXED_BASE, JT_FREE, JT_PRISMATIC, JT_REVOLUTE,
                                    JT_SPHERICAL, MF_AX, MF_TP, MF_TR, MI_JTYPE, MI_QI, W_XE, W_XR)
from toolkit.dynamics.spatial import axis_angle_to_rot, mat3_mul, quat_to_rot

__all__ = ["joint_transforms", "motion_col", "JT_FIXED_BASE", "JT_FREE", "JT_PRISMATIC",
           "JT_REVOLUTE", "JT_SPHERICAL"]


@njit(cache=True)
def joint_transforms(mi: np.ndarray, mf: np.ndarray, q: np.ndarray, wb: np.ndarray,
                     sc: np.ndarray) -> None:
    """Write every body's transform ``X_i = (E, r)`` into the workspace.

    Args:
        mi: packed integer model table ``(n_bodies, MI_COLS)``.
        mf: packed float model table ``(n_bodies, MF_COLS)``.
        q: generalised positions ``(n_q,)``.
        wb: per-body workspace ``(n_bodies, W_COLS)``.
        sc: scratch ``(>= 27,)``.
    """
    nb = mi.shape[0]
    RJ = sc[0:9]
    R = sc[9:18]
    for i in range(nb):
        jt = mi[i, MI_JTYPE]
        qi = mi[i, MI_QI]
        E = wb[i, W_XE:W_XE + 9]
        r = wb[i, W_XR:W_XR + 3]
        TR = mf[i, MF_TR:MF_TR + 9]
        TP = mf[i, MF_TP:MF_TP + 3]
        if jt == JT_FREE:
            x, y, z, w = q[qi + 3], q[qi + 4], q[qi + 5], q[qi + 6]
            n = math.sqrt(x * x + y * y + z * z + w * w)
            quat_to_rot(x / n, y / n, z / n, w / n, R)
            for a in range(3):
                r[a] = q[qi + a]
        elif jt == JT_FIXED_BASE:
            for a in range(9):
                R[a] = TR[a]
            for a in range(3):
                r[a] = TP[a]
        elif jt == JT_SPHERICAL:
            x, y, z, w = q[qi], q[qi + 1], q[qi + 2], q[qi + 3]
            n = math.sqrt(x * x + y * y + z * z + w * w)
            quat_to_rot(x / n, y / n, z / n, w / n, RJ)
            mat3_mul(TR, RJ, R)
            for a in range(3):
                r[a] = TP[a]
        elif jt == JT_REVOLUTE:
            axis_angle_to_rot(mf[i, MF_AX], mf[i, MF_AX + 1], mf[i, MF_AX + 2], q[qi], RJ)
            mat3_mul(TR, RJ, R)
            for a in range(3):
                r[a] = TP[a]
        else:  # prismatic: translate along the axis (joint frame) by q
            d = q[qi]
            for a in range(9):
                R[a] = TR[a]
            for a in range(3):
                r[a] = TP[a] + d * (TR[3 * a] * mf[i, MF_AX] + TR[3 * a + 1] * mf[i, MF_AX + 1]
                                    + TR[3 * a + 2] * mf[i, MF_AX + 2])
        # E = R^T
        for a in range(3):
            for b in range(3):
                E[3 * a + b] = R[3 * b + a]


@njit(cache=True, inline="always")
def motion_col(jt: int, ax: np.ndarray, k: int, out: np.ndarray) -> None:
    """Column ``k`` of a (non-root) joint's motion subspace ``S`` into ``out`` ``(6,)``."""
    for a in range(6):
        out[a] = 0.0
    if jt == JT_SPHERICAL:
        out[k] = 1.0
    elif jt == JT_REVOLUTE:
        out[0] = ax[0]
        out[1] = ax[1]
        out[2] = ax[2]
    else:
        out[3] = ax[0]
        out[4] = ax[1]
        out[5] = ax[2]
