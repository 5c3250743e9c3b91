"""Composite-rigid-body algorithm: the joint-space mass matrix ``M(q)`` (Featherstone RBDA §6.2).

Only entries ``M[i, j]`` with DoF ``j`` an ancestor of (or equal to) DoF ``i`` or vice versa are
written: that is the branch-induced sparsity the sparse LTL factorisation exploits. The other
entries of ``data.H`` are zero from construction and stay zero.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from toolkit.dynamics.kinematics import joint_transforms, motion_col
from toolkit.dynamics.model import (JT_REVOLUTE, JT_SPHERICAL, MF_AX, MF_IN, MI_JTYPE, MI_NV,
                                    MI_PARENT, MI_VI, W_IA, W_XE, W_XR)
from toolkit.dynamics.spatial import mat6_vec, xform_force_add, xform_inertia_add

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.dynamics.model import Data, Model


@njit(cache=True, inline="always")
def _root_col(E: np.ndarray, k: int, out: np.ndarray) -> None:
    """Column ``k`` of the floating-base subspace ``S_0 = [[0, E], [E, 0]]``."""
    for a in range(6):
        out[a] = 0.0
    if k < 3:  # linear velocity component k -> body linear part
        for a in range(3):
            out[3 + a] = E[3 * a + k]
    else:
        for a in range(3):
            out[a] = E[3 * a + k - 3]


@njit(cache=True, inline="always")
def _dot_col(jt: int, i: int, k: int, mf: np.ndarray, E: np.ndarray, F: np.ndarray) -> float:
    """``S_i[:, k]^T F`` for body ``i`` (``E`` is body i's transform, used for the root)."""
    if i == 0:
        if k < 3:
            return E[k] * F[3] + E[3 + k] * F[4] + E[6 + k] * F[5]
        kk = k - 3
        return E[kk] * F[0] + E[3 + kk] * F[1] + E[6 + kk] * F[2]
    if jt == JT_SPHERICAL:
        return F[k]
    if jt == JT_REVOLUTE:
        return mf[i, MF_AX] * F[0] + mf[i, MF_AX + 1] * F[1] + mf[i, MF_AX + 2] * F[2]
    return mf[i, MF_AX] * F[3] + mf[i, MF_AX + 1] * F[4] + mf[i, MF_AX + 2] * F[5]


@njit(cache=True)
def composite_inertias(mi: np.ndarray, mf: np.ndarray, wb: np.ndarray, sc: np.ndarray) -> None:
    """``IC_i`` = inertia of the subtree of ``i`` in ``wb[:, W_IA]`` (transforms must be set)."""
    nb = mi.shape[0]
    for i in range(nb):
        for a in range(36):
            wb[i, W_IA + a] = mf[i, MF_IN + a]
    for i in range(nb - 1, 0, -1):
        xform_inertia_add(wb[i, W_XE:W_XE + 9], wb[i, W_XR:W_XR + 3], wb[i, W_IA:W_IA + 36],
                          wb[mi[i, MI_PARENT], W_IA:W_IA + 36], sc[64:128])


@njit(cache=True)
def crba_kernel(mi: np.ndarray, mf: np.ndarray, q: np.ndarray, wb: np.ndarray, sc: np.ndarray,
                H: np.ndarray) -> None:
    """Mass matrix into ``H`` ``(n_v, n_v)`` (ancestor pairs only; see module docstring)."""
    nb = mi.shape[0]
    joint_transforms(mi, mf, q, wb, sc)
    composite_inertias(mi, mf, wb, sc)
    s = sc[18:24]
    F = sc[24:30]
    G = sc[30:36]
    for i in range(nb):
        jt = mi[i, MI_JTYPE]
        vi = mi[i, MI_VI]
        Ei = wb[i, W_XE:W_XE + 9]
        for k in range(mi[i, MI_NV]):
            if i == 0:
                _root_col(Ei, k, s)
            else:
                motion_col(jt, mf[i, MF_AX:MF_AX + 3], k, s)
            mat6_vec(wb[i, W_IA:W_IA + 36], s, F)
            for l in range(mi[i, MI_NV]):
                H[vi + k, vi + l] = _dot_col(jt, i, l, mf, Ei, F)
            j = i
            while mi[j, MI_PARENT] >= 0:
                for a in range(6):
                    G[a] = 0.0
                xform_force_add(wb[j, W_XE:W_XE + 9], wb[j, W_XR:W_XR + 3], F, G)
                for a in range(6):
                    F[a] = G[a]
                j = mi[j, MI_PARENT]
                vj = mi[j, MI_VI]
                jtj = mi[j, MI_JTYPE]
                for l in range(mi[j, MI_NV]):
                    h = _dot_col(jtj, j, l, mf, wb[j, W_XE:W_XE + 9], F)
                    H[vi + k, vj + l] = h
                    H[vj + l, vi + k] = h


def crba(model: "Model", data: "Data", q: np.ndarray) -> np.ndarray:
    """Joint-space mass matrix ``M(q)`` ``(n_v, n_v)`` (a copy of ``data.H``)."""
    crba_kernel(model.mi, model.mf, np.ascontiguousarray(q, dtype=np.float64), data.wb, data.sc,
                data.H)
    return data.H.copy()


__all__ = ["crba", "crba_kernel", "composite_inertias"]
