"""Compiled one-pose rotation conversions (numba, cached on disk) for the envs' per-step paths.

Each does on scalars what the vectorised ``rotations`` function does, in its order (numpy's
elementwise arithmetic, its sequential 3-element reductions and the C library's ``sin`` / ``cos``,
which numpy uses here too), so a PD target built here has the same bits as before
(``tests/toolkit/motion/test_motion_kernels.py`` holds each against the numpy path).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from toolkit.motion.rotations import SMALL


@njit(cache=True)
def quat_mul(ax: float, ay: float, az: float, aw: float, bx: float, by: float, bz: float, bw: float) -> tuple:
    """Hamilton product ``a b`` of two ``(x, y, z, w)`` quaternions given as scalars (the order of
    ``rotations.quat_multiply``'s terms, so the same bits); ``conj(a) b`` is ``quat_mul(-ax, -ay,
    -az, aw, ...)``, bit for bit the expanded form."""
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


@njit(cache=True)
def dofs_to_joints(dofs: np.ndarray, sph_dof: np.ndarray, sph_q: np.ndarray, rev_dof: np.ndarray,
                   rev_q: np.ndarray, out: np.ndarray) -> None:
    """``Skeleton.dofs_to_joints`` of one pose: dofs ``(n_dof,)`` -> ``out`` ``(n_q,)``.

    Args:
        sph_dof, sph_q: exp-map columns ``(n_spherical, 3)`` and quaternion columns ``(n_spherical, 4)``.
        rev_dof, rev_q: the other joints' dof and pose columns ``(n_revolute,)``.
    """
    for r in range(rev_dof.shape[0]):
        out[rev_q[r]] = dofs[rev_dof[r]]
    for s in range(sph_dof.shape[0]):
        v0, v1, v2 = dofs[sph_dof[s, 0]], dofs[sph_dof[s, 1]], dofs[sph_dof[s, 2]]
        theta = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
        if theta < SMALL:
            scale = 0.5 - theta * theta / 48.0
        else:
            scale = math.sin(0.5 * theta) / theta
        out[sph_q[s, 0]] = v0 * scale
        out[sph_q[s, 1]] = v1 * scale
        out[sph_q[s, 2]] = v2 * scale
        out[sph_q[s, 3]] = math.cos(0.5 * theta)


@njit(cache=True)
def clip_small_expmaps(dofs: np.ndarray, sph_dof: np.ndarray, low: np.ndarray, high: np.ndarray,
                       out: np.ndarray) -> bool:
    """``limits.limit_targets`` of one pose whose exp maps are all canonical already: ``out`` =
    ``np.clip(dofs, low, high)`` and True; False (``out`` untouched) if an exp map has ``|v|² > π²``
    (its canonical form needs the numpy path's ``arctan2``)."""
    for s in range(sph_dof.shape[0]):
        v0, v1, v2 = dofs[sph_dof[s, 0]], dofs[sph_dof[s, 1]], dofs[sph_dof[s, 2]]
        if v0 * v0 + v1 * v1 + v2 * v2 > np.pi ** 2:
            return False
    for j in range(dofs.shape[0]):
        x = dofs[j]
        out[j] = low[j] if x < low[j] else (high[j] if x > high[j] else x)
    return True


@njit(cache=True)
def bspline_basis(s: np.ndarray, knots: np.ndarray, degree: int, out: np.ndarray) -> None:
    """``splines.basis_matrix`` at ``s`` ``(n,)`` into ``out`` ``(n, n_control)``: its Cox-de Boor
    recursion with the same operations per basis (the same bits)."""
    lo, hi = knots[degree], knots[knots.shape[0] - degree - 1]
    m = knots.shape[0] - 1
    last = 0
    for j in range(m):
        if knots[j] < knots[j + 1]:
            last = j
    b = np.empty(m)
    for r in range(s.shape[0]):
        x = min(max(s[r], lo), hi)
        span = min(np.searchsorted(knots, x, side="right") - 1, last)
        for j in range(m):
            b[j] = 1.0 if j == span else 0.0
        for d in range(1, degree + 1):
            for j in range(m - d):
                ld = knots[d + j] - knots[j]
                rd = knots[d + 1 + j] - knots[1 + j]
                left = (x - knots[j]) / ld if ld > 0 else 0.0
                right = (knots[d + 1 + j] - x) / rd if rd > 0 else 0.0
                b[j] = left * b[j] + right * b[j + 1]
        for j in range(out.shape[1]):
            out[r, j] = b[j]
