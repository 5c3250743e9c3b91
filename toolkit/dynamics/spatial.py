"""Spatial algebra (Featherstone, *Rigid Body Dynamics Algorithms*, ch. 2) as numba kernels.

Conventions:
    * 6D vectors are ``[angular; linear]``: motion vectors ``[w; v]``, force vectors ``[n; f]``.
    * A coordinate transform ``X`` from frame A to frame B is stored as ``(E, r)``: ``E`` ``(9,)``
      is the row-major 3x3 rotation taking A coordinates to B coordinates (``E = R^T`` where ``R``
      is B's orientation in A) and ``r`` ``(3,)`` is B's origin in A coordinates, so
      ``X = [[E, 0], [-E r^, E]]``.
    * Quaternions are ``x, y, z, w`` (PyBullet's order).

Everything here works on flat float64 arrays (or views of rows of the model/workspace arrays)
without allocating, so the algorithm kernels can call these per body per call.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# ------------------------------------------------------------------------------------------------
# quaternions and rotations
# ------------------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def quat_to_rot(x: float, y: float, z: float, w: float, R: np.ndarray) -> None:
    """Rotation matrix of a unit quaternion, written row-major into ``R`` ``(9,)``."""
    R[0] = 1.0 - 2.0 * (y * y + z * z)
    R[1] = 2.0 * (x * y - z * w)
    R[2] = 2.0 * (x * z + y * w)
    R[3] = 2.0 * (x * y + z * w)
    R[4] = 1.0 - 2.0 * (x * x + z * z)
    R[5] = 2.0 * (y * z - x * w)
    R[6] = 2.0 * (x * z - y * w)
    R[7] = 2.0 * (y * z + x * w)
    R[8] = 1.0 - 2.0 * (x * x + y * y)


@njit(cache=True, inline="always")
def quat_mul(ax, ay, az, aw, bx, by, bz, bw):
    """Hamilton product ``a * b`` of two ``x, y, z, w`` quaternions, as a 4-tuple."""
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


@njit(cache=True, inline="always")
def quat_exp(vx: float, vy: float, vz: float):
    """Unit quaternion of the rotation vector ``v`` (axis * angle), as a 4-tuple."""
    th = math.sqrt(vx * vx + vy * vy + vz * vz)
    if th < 1e-12:
        return (0.5 * vx, 0.5 * vy, 0.5 * vz, 1.0)
    s = math.sin(0.5 * th) / th
    return (s * vx, s * vy, s * vz, math.cos(0.5 * th))


@njit(cache=True, inline="always")
def quat_log(x: float, y: float, z: float, w: float):
    """Rotation vector (axis * angle, angle in [0, pi]) of a quaternion, as a 3-tuple.

    The quaternion need not be normalised; ``q`` and ``-q`` give the same (shortest) rotation.
    """
    if w < 0.0:
        x, y, z, w = -x, -y, -z, -w
    s = math.sqrt(x * x + y * y + z * z)
    if s < 1e-12:
        n = math.sqrt(x * x + y * y + z * z + w * w)
        return (2.0 * x / n, 2.0 * y / n, 2.0 * z / n)
    k = 2.0 * math.atan2(s, w) / s
    return (k * x, k * y, k * z)


@njit(cache=True, inline="always")
def axis_angle_to_rot(ax: float, ay: float, az: float, th: float, R: np.ndarray) -> None:
    """Rotation by ``th`` about the unit axis ``a``, row-major into ``R`` ``(9,)``."""
    c = math.cos(th)
    s = math.sin(th)
    t = 1.0 - c
    R[0] = t * ax * ax + c
    R[1] = t * ax * ay - s * az
    R[2] = t * ax * az + s * ay
    R[3] = t * ax * ay + s * az
    R[4] = t * ay * ay + c
    R[5] = t * ay * az - s * ax
    R[6] = t * ax * az - s * ay
    R[7] = t * ay * az + s * ax
    R[8] = t * az * az + c


@njit(cache=True, inline="always")
def mat3_mul(A: np.ndarray, B: np.ndarray, out: np.ndarray) -> None:
    """``out = A @ B`` for row-major 3x3 matrices ``(9,)`` (``out`` must not alias)."""
    for i in range(3):
        for j in range(3):
            out[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j]


# ------------------------------------------------------------------------------------------------
# spatial transforms
# ------------------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def xform_motion(E: np.ndarray, r: np.ndarray, v: np.ndarray, out: np.ndarray) -> None:
    """``out = X v`` for a motion vector (A coordinates -> B coordinates)."""
    w0, w1, w2 = v[0], v[1], v[2]
    u0 = v[3] - (r[1] * w2 - r[2] * w1)
    u1 = v[4] - (r[2] * w0 - r[0] * w2)
    u2 = v[5] - (r[0] * w1 - r[1] * w0)
    out[0] = E[0] * w0 + E[1] * w1 + E[2] * w2
    out[1] = E[3] * w0 + E[4] * w1 + E[5] * w2
    out[2] = E[6] * w0 + E[7] * w1 + E[8] * w2
    out[3] = E[0] * u0 + E[1] * u1 + E[2] * u2
    out[4] = E[3] * u0 + E[4] * u1 + E[5] * u2
    out[5] = E[6] * u0 + E[7] * u1 + E[8] * u2


@njit(cache=True, inline="always")
def xform_force_add(E: np.ndarray, r: np.ndarray, f: np.ndarray, out: np.ndarray) -> None:
    """``out += X^T f`` for a force vector (B coordinates -> A coordinates)."""
    n0 = E[0] * f[0] + E[3] * f[1] + E[6] * f[2]
    n1 = E[1] * f[0] + E[4] * f[1] + E[7] * f[2]
    n2 = E[2] * f[0] + E[5] * f[1] + E[8] * f[2]
    g0 = E[0] * f[3] + E[3] * f[4] + E[6] * f[5]
    g1 = E[1] * f[3] + E[4] * f[4] + E[7] * f[5]
    g2 = E[2] * f[3] + E[5] * f[4] + E[8] * f[5]
    out[0] += n0 + r[1] * g2 - r[2] * g1
    out[1] += n1 + r[2] * g0 - r[0] * g2
    out[2] += n2 + r[0] * g1 - r[1] * g0
    out[3] += g0
    out[4] += g1
    out[5] += g2


@njit(cache=True)
def xform_inertia_add(E: np.ndarray, r: np.ndarray, I: np.ndarray, out: np.ndarray,
                      s: np.ndarray) -> None:
    """``out += X^T I X`` for a symmetric 6x6 (articulated) inertia, row-major ``(36,)``.

    With ``I = [[A, B], [B^T, D]]`` (3x3 blocks, ``A``, ``D`` symmetric) and
    ``X = blockdiag(E, E) [[1, 0], [-r^, 1]]``: rotate the blocks (``A' = E^T A E`` ...), then
    ``out_A += A' - B' r^ + r^ B'^T - r^ D' r^``, ``out_B += B' + r^ D'``, ``out_D += D'``.
    Symmetric blocks are computed on their upper triangle only. ``s`` is scratch of at least 54
    floats (no allocation).
    """
    # s[0:9] A', s[9:18] B', s[18:27] D', s[27:36] M E, s[36:45] B' r^, s[45:54] r^ D'
    for blk in range(3):
        ro = 3 if blk == 2 else 0  # A = I[0:3, 0:3], B = I[0:3, 3:6], D = I[3:6, 3:6]
        co = 0 if blk == 0 else 3
        for i in range(3):
            m0 = I[6 * (ro + i) + co]
            m1 = I[6 * (ro + i) + co + 1]
            m2 = I[6 * (ro + i) + co + 2]
            for j in range(3):
                s[27 + 3 * i + j] = m0 * E[j] + m1 * E[3 + j] + m2 * E[6 + j]
        o = 9 * blk
        if blk == 1:
            for i in range(3):
                for j in range(3):
                    s[o + 3 * i + j] = (E[i] * s[27 + j] + E[3 + i] * s[30 + j]
                                        + E[6 + i] * s[33 + j])
        else:
            for i in range(3):
                for j in range(i, 3):
                    v = E[i] * s[27 + j] + E[3 + i] * s[30 + j] + E[6 + i] * s[33 + j]
                    s[o + 3 * i + j] = v
                    s[o + 3 * j + i] = v
    r0, r1, r2 = r[0], r[1], r[2]
    # r^ = [[0, -r2, r1], [r2, 0, -r0], [-r1, r0, 0]]
    for i in range(3):
        b0, b1, b2 = s[9 + 3 * i], s[10 + 3 * i], s[11 + 3 * i]
        s[36 + 3 * i] = b1 * r2 - b2 * r1
        s[37 + 3 * i] = b2 * r0 - b0 * r2
        s[38 + 3 * i] = b0 * r1 - b1 * r0
    for j in range(3):
        d0, d1, d2 = s[18 + j], s[21 + j], s[24 + j]
        s[45 + j] = r1 * d2 - r2 * d1
        s[48 + j] = r2 * d0 - r0 * d2
        s[51 + j] = r0 * d1 - r1 * d0
    for i in range(3):
        x0, x1, x2 = s[45 + 3 * i], s[46 + 3 * i], s[47 + 3 * i]
        # row i of (r^ D') r^
        rdr0 = x1 * r2 - x2 * r1
        rdr1 = x2 * r0 - x0 * r2
        rdr2 = x0 * r1 - x1 * r0
        for j in range(3):
            rdr = rdr0 if j == 0 else (rdr1 if j == 1 else rdr2)
            b = s[9 + 3 * i + j] + s[45 + 3 * i + j]
            out[6 * i + 3 + j] += b
            out[6 * (3 + j) + i] += b
            out[6 * (3 + i) + 3 + j] += s[18 + 3 * i + j]
            if j >= i:
                a = s[3 * i + j] - s[36 + 3 * i + j] - s[36 + 3 * j + i] - rdr
                out[6 * i + j] += a
                if j > i:
                    out[6 * j + i] += a


# ------------------------------------------------------------------------------------------------
# cross products and inertia products
# ------------------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def cross_motion(v: np.ndarray, m: np.ndarray, out: np.ndarray) -> None:
    """``out = v x m`` (motion cross product, Featherstone's ``crm(v) m``)."""
    w0, w1, w2, u0, u1, u2 = v[0], v[1], v[2], v[3], v[4], v[5]
    a0, a1, a2, b0, b1, b2 = m[0], m[1], m[2], m[3], m[4], m[5]
    out[0] = w1 * a2 - w2 * a1
    out[1] = w2 * a0 - w0 * a2
    out[2] = w0 * a1 - w1 * a0
    out[3] = w1 * b2 - w2 * b1 + u1 * a2 - u2 * a1
    out[4] = w2 * b0 - w0 * b2 + u2 * a0 - u0 * a2
    out[5] = w0 * b1 - w1 * b0 + u0 * a1 - u1 * a0


@njit(cache=True, inline="always")
def cross_force_add(v: np.ndarray, f: np.ndarray, out: np.ndarray) -> None:
    """``out += v x* f`` (force cross product, Featherstone's ``crf(v) f``)."""
    w0, w1, w2, u0, u1, u2 = v[0], v[1], v[2], v[3], v[4], v[5]
    n0, n1, n2, g0, g1, g2 = f[0], f[1], f[2], f[3], f[4], f[5]
    out[0] += w1 * n2 - w2 * n1 + u1 * g2 - u2 * g1
    out[1] += w2 * n0 - w0 * n2 + u2 * g0 - u0 * g2
    out[2] += w0 * n1 - w1 * n0 + u0 * g1 - u1 * g0
    out[3] += w1 * g2 - w2 * g1
    out[4] += w2 * g0 - w0 * g2
    out[5] += w0 * g1 - w1 * g0


@njit(cache=True, inline="always")
def mat6_vec(I: np.ndarray, v: np.ndarray, out: np.ndarray) -> None:
    """``out = I v`` for a row-major 6x6 matrix ``(36,)``."""
    for i in range(6):
        s = 0.0
        for j in range(6):
            s += I[6 * i + j] * v[j]
        out[i] = s


@njit(cache=True, inline="always")
def mat6_vec_add(I: np.ndarray, v: np.ndarray, out: np.ndarray) -> None:
    """``out += I v`` for a row-major 6x6 matrix ``(36,)``."""
    for i in range(6):
        s = 0.0
        for j in range(6):
            s += I[6 * i + j] * v[j]
        out[i] += s


def spatial_inertia(mass: float, com: np.ndarray, I_com: np.ndarray) -> np.ndarray:
    """Spatial inertia ``(6, 6)`` of a rigid body about its frame origin (plain numpy).

    Args:
        mass: mass in kg.
        com: centre of mass in the body frame ``(3,)``.
        I_com: rotational inertia about the centre of mass, body axes ``(3, 3)``.
    """
    c = np.asarray(com, dtype=float)
    cx = np.array([[0.0, -c[2], c[1]], [c[2], 0.0, -c[0]], [-c[1], c[0], 0.0]])
    out = np.zeros((6, 6))
    out[:3, :3] = I_com + mass * cx @ cx.T
    out[:3, 3:] = mass * cx
    out[3:, :3] = mass * cx.T
    out[3:, 3:] = mass * np.eye(3)
    return out
