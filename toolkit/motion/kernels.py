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


@njit(cache=True)
def _sixd_columns(x: np.ndarray, c: np.ndarray, eps: float) -> tuple:
    """``rotations.sixd_to_matrix`` of the 6D block at columns ``c`` ``(6,)`` of ``x``: the columns
    ``b1, b2, b3`` of the matrix as nine scalars, in that function's operations."""
    a0, a1, a2 = x[c[0]], x[c[1]], x[c[2]]
    d0, d1, d2 = x[c[3]], x[c[4]], x[c[5]]
    n1 = math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
    if n1 > eps:
        m1 = max(n1, eps)
        b10, b11, b12 = a0 / m1, a1 / m1, a2 / m1
    else:
        b10, b11, b12 = 1.0, 0.0, 0.0
    dot = b10 * d0 + b11 * d1 + b12 * d2
    b20, b21, b22 = d0 - dot * b10, d1 - dot * b11, d2 - dot * b12
    n2 = math.sqrt(b20 * b20 + b21 * b21 + b22 * b22)
    if n2 > 1e-9:
        m2 = max(n2, eps)
        b20, b21, b22 = b20 / m2, b21 / m2, b22 / m2
    else:  # degenerate second column: a unit vector orthogonal to b1
        u0, u1, u2 = (1.0, 0.0, 0.0) if abs(b10) < 0.9 else (0.0, 1.0, 0.0)
        c0, c1, c2 = b11 * u2 - b12 * u1, b12 * u0 - b10 * u2, b10 * u1 - b11 * u0
        na = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
        b20, b21, b22 = c0 / na, c1 / na, c2 / na
    b30, b31, b32 = b11 * b22 - b12 * b21, b12 * b20 - b10 * b22, b10 * b21 - b11 * b20
    return b10, b11, b12, b20, b21, b22, b30, b31, b32


@njit(cache=True)
def _unit_canonical(x: float, y: float, z: float, w: float, eps: float) -> tuple:
    """``quat_canonical(quat_normalize(q))`` of one quaternion."""
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if n > eps:
        m = max(n, eps)
        x, y, z, w = x / m, y / m, z / m, w / m
    else:
        x, y, z, w = 0.0, 0.0, 0.0, 1.0
    if w < 0.0:
        return -x, -y, -z, -w
    return x, y, z, w


@njit(cache=True)
def features_to_dofs_pre(x: np.ndarray, cols: np.ndarray, sph: np.ndarray, rev: np.ndarray, e: np.ndarray,
                         f: np.ndarray, eps: float, quat: np.ndarray, ys: np.ndarray, xs: np.ndarray) -> None:
    """``toolkit.priors.model.TargetMap`` of one pose up to its ``arctan2`` calls, which numpy's
    vectorised ``arctan2`` then does (its bits differ from the C library's ``atan2`` numba calls
    in the last digit): raw features ``x`` ``(n_features,)`` -> each joint's 6D block to a matrix
    (Gram-Schmidt); a spherical joint's to its canonical unit quaternion (Shepperd, normalised as
    ``quat_to_expmap`` does); the arguments of the angles.

    Args:
        cols: each joint's 6D columns ``(n_joints, 6)``.
        sph, rev: the spherical joints ``(n_sph,)`` and the revolute ones ``(n_rev,)``.
        e, f: per revolute joint, two unit vectors orthogonal to its axis ``(n_rev, 3)``.
        eps: ``rotations.EPS``.
        quat: written, the spherical joints' quaternions ``(n_sph, 4)``.
        ys, xs: written, ``arctan2``'s arguments ``(n_sph + n_rev,)``: ``(|q_xyz|, q_w)`` per
            spherical joint (its log map's angle), then the revolute joints'.
    """
    n_sph = sph.shape[0]
    for s in range(n_sph):
        m00, m10, m20, m01, m11, m21, m02, m12, m22 = _sixd_columns(x, cols[sph[s]], eps)
        t0, t1, t2, t3 = m00 - m11 - m22, m11 - m00 - m22, m22 - m00 - m11, m00 + m11 + m22
        k, best = 0, t0  # np.argmax: the first of equal maxima
        if t1 > best:
            k, best = 1, t1
        if t2 > best:
            k, best = 2, t2
        if t3 > best:
            k = 3
        if k == 0:
            q = (1 + m00 - m11 - m22, m01 + m10, m02 + m20, m21 - m12)
        elif k == 1:
            q = (m01 + m10, 1 - m00 + m11 - m22, m12 + m21, m02 - m20)
        elif k == 2:
            q = (m02 + m20, m12 + m21, 1 - m00 - m11 + m22, m10 - m01)
        else:
            q = (m21 - m12, m02 - m20, m10 - m01, 1 + m00 + m11 + m22)
        qx, qy, qz, qw = _unit_canonical(q[0], q[1], q[2], q[3], eps)  # matrix_to_quat
        qx, qy, qz, qw = _unit_canonical(qx, qy, qz, qw, eps)  # quat_to_expmap's own
        quat[s, 0], quat[s, 1], quat[s, 2], quat[s, 3] = qx, qy, qz, qw
        ys[s] = math.sqrt(qx * qx + qy * qy + qz * qz)
        xs[s] = qw
    for r in range(rev.shape[0]):
        m00, m10, m20, m01, m11, m21, m02, m12, m22 = _sixd_columns(x, cols[rev[r]], eps)
        e0, e1, e2 = e[r, 0], e[r, 1], e[r, 2]
        r0 = m00 * e0 + m01 * e1 + m02 * e2
        r1 = m10 * e0 + m11 * e1 + m12 * e2
        r2 = m20 * e0 + m21 * e1 + m22 * e2
        ys[n_sph + r] = r0 * f[r, 0] + r1 * f[r, 1] + r2 * f[r, 2]
        xs[n_sph + r] = r0 * e0 + r1 * e1 + r2 * e2


@njit(cache=True)
def features_to_dofs_post(quat: np.ndarray, angles: np.ndarray, sph_dofs: np.ndarray, rev_dofs: np.ndarray,
                          out: np.ndarray) -> None:
    """The rest of ``features_to_dofs_pre``: PD targets ``out`` ``(n_dof,)`` from the quaternions
    ``(n_sph, 4)`` and ``angles = np.arctan2(ys, xs)`` ``(n_sph + n_rev,)``: each spherical joint's
    exp map (``quat_to_expmap``: its series below ``SMALL``) at ``sph_dofs`` ``(n_sph, 3)``, each
    revolute joint's angle at ``rev_dofs`` ``(n_rev,)``."""
    n_sph = sph_dofs.shape[0]
    for s in range(n_sph):
        qx, qy, qz, qw = quat[s, 0], quat[s, 1], quat[s, 2], quat[s, 3]
        sn = math.sqrt(qx * qx + qy * qy + qz * qz)
        if sn < SMALL:
            scale = (2.0 / qw) * (1.0 - sn * sn / (3.0 * (qw * qw)))
        else:
            scale = 2.0 * angles[s] / sn
        out[sph_dofs[s, 0]] = qx * scale
        out[sph_dofs[s, 1]] = qy * scale
        out[sph_dofs[s, 2]] = qz * scale
    for r in range(rev_dofs.shape[0]):
        out[rev_dofs[r]] = angles[n_sph + r]
