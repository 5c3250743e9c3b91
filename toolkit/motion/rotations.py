"""Rotation utilities in jt's convention, numpy only.

Conventions (used everywhere in jt):

* Quaternions are stored ``(x, y, z, w)`` (PyBullet's and scipy's order), Hamilton product,
  unit norm. ``q`` and ``-q`` are the same rotation; functions that return a quaternion from a
  non-quaternion input return the canonical one (``w >= 0``).
* A rotation matrix ``R`` maps local to world coordinates: ``v_world = R @ v_local``, and
  ``quat_rotate(q, v) == quat_to_matrix(q) @ v``.
* The exponential map (rotation vector) ``v = angle * axis`` with ``angle = |v|``; the log map
  returns ``|v| <= pi``.
* The 6D representation (Zhou et al. 2019) is the first two *columns* of ``R`` concatenated:
  ``(R[0,0], R[1,0], R[2,0], R[0,1], R[1,1], R[2,1])``; it maps back by Gram-Schmidt.

Every function is vectorised over leading dimensions: quaternions ``(..., 4)``, vectors
``(..., 3)``, matrices ``(..., 3, 3)``, 6D ``(..., 6)``, angles ``(...)``.
"""

from __future__ import annotations

import math

import numpy as np

EPS = 1e-12
"""Below this norm a vector or quaternion counts as zero (no direction to normalise to)."""
SMALL = 1e-6
"""Below this angle ``|v|`` (or half-angle sine) a Taylor series replaces the closed form. The
compiled kernels (``toolkit.motion.kernels``, the spacetime and get-up envs' ``kernels``) import
both constants from here, so they take the same branches as the numpy functions."""


def _arr(x) -> np.ndarray:
    return np.asarray(x, dtype=np.float64)


def quat_identity(shape: tuple[int, ...] = ()) -> np.ndarray:
    """Identity quaternions of shape ``(*shape, 4)``."""
    q = np.zeros(tuple(shape) + (4,))
    q[..., 3] = 1.0
    return q


def quat_normalize(q) -> np.ndarray:
    """Unit quaternions ``(..., 4)``; a zero quaternion becomes the identity."""
    q = _arr(q)
    if q.shape == (4,):  # one quaternion: Python floats, the same bits (see _quat_to_matrix_one)
        x, y, z, w = q.tolist()
        n = math.sqrt(x * x + y * y + z * z + w * w)
        return np.array([x / n, y / n, z / n, w / n] if n > EPS else [0.0, 0.0, 0.0, 1.0])
    n = np.linalg.norm(q, axis=-1, keepdims=True)
    out = q / np.maximum(n, EPS)
    return np.where(n > EPS, out, quat_identity(q.shape[:-1]))


def quat_canonical(q) -> np.ndarray:
    """The same rotations with ``w >= 0`` ``(..., 4)`` (the double-cover representative)."""
    q = _arr(q)
    if q.shape == (4,):
        return -q if q[3] < 0.0 else q.copy()
    return np.where(q[..., 3:4] < 0.0, -q, q)


def quat_conjugate(q) -> np.ndarray:
    """Conjugate ``(-x, -y, -z, w)``; the inverse of a unit quaternion ``(..., 4)``."""
    q = _arr(q)
    return np.concatenate([-q[..., :3], q[..., 3:]], axis=-1)


def quat_multiply(a, b) -> np.ndarray:
    """Hamilton product ``a * b`` ``(..., 4)``: rotate by ``b`` first, then by ``a``."""
    a, b = _arr(a), _arr(b)
    if a.shape == b.shape == (4,):  # two quaternions: Python floats, the same sums in the same order
        ax, ay, az, aw = a.tolist()
        bx, by, bz, bw = b.tolist()
        return np.array([aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                         aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz])
    a, b = np.broadcast_arrays(a, b)
    ax, ay, az, aw = np.moveaxis(a, -1, 0)
    bx, by, bz, bw = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ],
        axis=-1,
    )


def quat_rotate(q, v) -> np.ndarray:
    """Rotate vectors ``v`` ``(..., 3)`` by unit quaternions ``q`` ``(..., 4)``."""
    q, v = _arr(q), _arr(v)
    if q.shape == (4,):  # one rotation (the envs' per-step frames): the same operations, fewer calls
        return _rotate_by_one(q, v)
    u, w = q[..., :3], q[..., 3:4]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def _rotate_by_one(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``quat_rotate`` of vectors ``v`` ``(..., 3)`` by one quaternion ``q`` ``(4,)``, bit for bit:
    ``v + w t + u × t`` with ``t = 2 (u × v)``, each product and sum in ``np.cross``'s order, on
    Python floats for one vector and on ``v``'s columns for many."""
    x, y, z, w = q.tolist()
    if v.shape == (3,):
        vx, vy, vz = v.tolist()
    else:
        vx, vy, vz = v[..., 0], v[..., 1], v[..., 2]
    tx, ty, tz = 2.0 * (y * vz - z * vy), 2.0 * (z * vx - x * vz), 2.0 * (x * vy - y * vx)
    out = (vx + w * tx + (y * tz - z * ty), vy + w * ty + (z * tx - x * tz), vz + w * tz + (x * ty - y * tx))
    return np.array(out) if v.shape == (3,) else np.stack(out, axis=-1)


def quat_relative(a, b) -> np.ndarray:
    """``conj(a) * b``: the rotation taking ``a`` to ``b`` expressed in ``a``'s frame ``(..., 4)``."""
    return quat_multiply(quat_conjugate(a), b)


def quat_angle(a, b=None) -> np.ndarray:
    """Rotation angle in ``[0, pi]`` of ``a`` (or of ``conj(a) * b``), sign-insensitive ``(...)``."""
    q = _arr(a) if b is None else quat_relative(a, b)
    return 2.0 * np.arctan2(np.linalg.norm(q[..., :3], axis=-1), np.abs(q[..., 3]))


# --------------------------------------------------------------------------- exp / log / axis-angle


def quat_from_expmap(v) -> np.ndarray:
    """Exponential map: rotation vectors ``(..., 3)`` → unit quaternions ``(..., 4)``.

    Exact for any ``|v|`` (``|v| > pi`` gives ``w < 0``, still the right rotation); a Taylor
    series is used for ``|v| < 1e-6``.
    """
    v = _arr(v)
    theta = np.linalg.norm(v, axis=-1, keepdims=True)
    small = theta < SMALL
    safe = np.where(small, 1.0, theta)
    scale = np.where(small, 0.5 - theta**2 / 48.0, np.sin(0.5 * safe) / safe)
    return np.concatenate([v * scale, np.cos(0.5 * theta)], axis=-1)


def quat_to_expmap(q) -> np.ndarray:
    """Log map: quaternions ``(..., 4)`` → rotation vectors ``(..., 3)`` with ``|v| <= pi``.

    ``q`` and ``-q`` give the same result (the ``w >= 0`` representative is used). Robust near
    the identity (series) and near ``pi`` (``atan2`` rather than ``acos``).
    """
    q = quat_canonical(quat_normalize(q))
    u, w = q[..., :3], q[..., 3:4]
    s = np.linalg.norm(u, axis=-1, keepdims=True)
    small = s < SMALL
    safe = np.where(small, 1.0, s)
    # angle = 2 atan2(s, w); angle / s -> 2 / w (1 - s^2 / (3 w^2)) as s -> 0 (w ~ 1 there)
    scale = np.where(small, (2.0 / w) * (1.0 - s**2 / (3.0 * w**2)), 2.0 * np.arctan2(s, w) / safe)
    return u * scale


quat_exp = quat_from_expmap
quat_log = quat_to_expmap


def quat_from_axis_angle(axis, angle) -> np.ndarray:
    """Quaternions ``(..., 4)`` from axes ``(..., 3)`` (normalised here) and angles ``(...)``."""
    axis = _arr(axis)
    n = np.linalg.norm(axis, axis=-1, keepdims=True)
    axis = axis / np.maximum(n, EPS)
    half = 0.5 * _arr(angle)[..., None]
    xyz = axis * np.sin(half)
    w = np.broadcast_to(np.cos(half), xyz.shape[:-1] + (1,))
    return np.concatenate([xyz, w], axis=-1)


def quat_to_axis_angle(q) -> tuple[np.ndarray, np.ndarray]:
    """Unit axes ``(..., 3)`` and angles ``(...)`` in ``[0, pi]``; axis ``(1, 0, 0)`` at angle 0."""
    v = quat_to_expmap(q)
    angle = np.linalg.norm(v, axis=-1)
    axis = np.where(
        angle[..., None] > EPS, v / np.maximum(angle, EPS)[..., None], np.array([1.0, 0.0, 0.0])
    )
    return axis, angle


def quat_slerp(q0, q1, t) -> np.ndarray:
    """Spherical linear interpolation along the shortest arc ``(..., 4)``.

    Args:
        q0: start quaternions ``(..., 4)``.
        q1: end quaternions ``(..., 4)``; ``q1`` and ``-q1`` give the same path.
        t: fractions ``(...)`` (broadcast against the leading dims); 0 → ``q0``, 1 → ``±q1``.
    """
    q0 = quat_normalize(q0)
    rel = quat_canonical(quat_relative(q0, quat_normalize(q1)))
    step = quat_from_expmap(quat_to_expmap(rel) * _arr(t)[..., None])
    return quat_multiply(q0, step)


# --------------------------------------------------------------------------- matrices and 6D


def quat_to_matrix(q) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` of quaternions ``(..., 4)`` (normalised here)."""
    q = _arr(q)
    if q.shape == (4,):  # one quaternion (every env's per-step observation): Python floats, same bits
        return _quat_to_matrix_one(q)
    x, y, z, w = np.moveaxis(quat_normalize(q), -1, 0)
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz, wx, wy, wz = x * y, x * z, y * z, w * x, w * y, w * z
    m = np.stack(
        [
            1 - 2 * (yy + zz), 2 * (xy - wz), 2 * (xz + wy),
            2 * (xy + wz), 1 - 2 * (xx + zz), 2 * (yz - wx),
            2 * (xz - wy), 2 * (yz + wx), 1 - 2 * (xx + yy),
        ],
        axis=-1,
    )  # fmt: skip
    return m.reshape(m.shape[:-1] + (3, 3))


def _quat_to_matrix_one(q: np.ndarray) -> np.ndarray:
    """``quat_to_matrix`` of one quaternion ``(4,)`` → ``(3, 3)``, bit for bit: the same operations
    in the same order as the vectorised path (``quat_normalize``'s norm sums the squares left to
    right, as numpy's reduction of four values does), on Python floats (~10x faster than numpy's
    per-call overhead on 4 numbers)."""
    x, y, z, w = q.tolist()
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if n > EPS:
        x, y, z, w = x / n, y / n, z / n, w / n
    else:
        x, y, z, w = 0.0, 0.0, 0.0, 1.0
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz, wx, wy, wz = x * y, x * z, y * z, w * x, w * y, w * z
    return np.array([[1 - 2 * (yy + zz), 2 * (xy - wz), 2 * (xz + wy)],
                     [2 * (xy + wz), 1 - 2 * (xx + zz), 2 * (yz - wx)],
                     [2 * (xz - wy), 2 * (yz + wx), 1 - 2 * (xx + yy)]])


def matrix_to_quat(m) -> np.ndarray:
    """Canonical (``w >= 0``) unit quaternions ``(..., 4)`` of rotation matrices ``(..., 3, 3)``.

    Uses the numerically best of the four Shepperd candidates per matrix, so it is accurate for
    all angles including ``pi``.
    """
    m = _arr(m)
    m00, m11, m22 = m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]
    cands = np.stack(
        [
            np.stack([1 + m00 - m11 - m22, m[..., 0, 1] + m[..., 1, 0],
                      m[..., 0, 2] + m[..., 2, 0], m[..., 2, 1] - m[..., 1, 2]], -1),
            np.stack([m[..., 0, 1] + m[..., 1, 0], 1 - m00 + m11 - m22,
                      m[..., 1, 2] + m[..., 2, 1], m[..., 0, 2] - m[..., 2, 0]], -1),
            np.stack([m[..., 0, 2] + m[..., 2, 0], m[..., 1, 2] + m[..., 2, 1],
                      1 - m00 - m11 + m22, m[..., 1, 0] - m[..., 0, 1]], -1),
            np.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0],
                      m[..., 1, 0] - m[..., 0, 1], 1 + m00 + m11 + m22], -1),
        ],
        axis=-2,
    )  # fmt: skip  # (..., 4 candidates, 4); candidate k has component k = 4 q_k^2
    k = np.argmax(np.stack([m00 - m11 - m22, m11 - m00 - m22, m22 - m00 - m11, m00 + m11 + m22], -1), -1)
    q = np.take_along_axis(cands, k[..., None, None], axis=-2)[..., 0, :]
    return quat_canonical(quat_normalize(q))


def matrix_to_6d(m) -> np.ndarray:
    """First two columns of ``R`` ``(..., 3, 3)`` → ``(..., 6)`` = ``(col0, col1)``."""
    m = _arr(m)
    return np.concatenate([m[..., :, 0], m[..., :, 1]], axis=-1)


def sixd_to_matrix(d6) -> np.ndarray:
    """Gram-Schmidt of a 6D vector ``(..., 6)`` into a rotation matrix ``(..., 3, 3)``.

    Any input is accepted (the network outputs of a decoder need not be orthonormal); a zero or
    degenerate pair still yields a finite orthonormal matrix.
    """
    d6 = _arr(d6)
    a1, a2 = d6[..., :3], d6[..., 3:]
    n1 = np.linalg.norm(a1, axis=-1, keepdims=True)
    b1 = np.where(n1 > EPS, a1 / np.maximum(n1, EPS), [1.0, 0.0, 0.0])
    b2 = a2 - np.sum(b1 * a2, axis=-1, keepdims=True) * b1
    n2 = np.linalg.norm(b2, axis=-1, keepdims=True)
    # degenerate second column: use a unit vector orthogonal to b1
    alt = np.cross(b1, np.where(np.abs(b1[..., :1]) < 0.9, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]))
    alt = alt / np.linalg.norm(alt, axis=-1, keepdims=True)
    b2 = np.where(n2 > 1e-9, b2 / np.maximum(n2, EPS), alt)
    b3 = np.cross(b1, b2)
    return np.stack([b1, b2, b3], axis=-1)


def quat_to_6d(q) -> np.ndarray:
    """Quaternions ``(..., 4)`` → 6D ``(..., 6)`` (sign-insensitive: ``q`` and ``-q`` agree)."""
    return matrix_to_6d(quat_to_matrix(q))


def sixd_to_quat(d6) -> np.ndarray:
    """6D ``(..., 6)`` → canonical unit quaternions ``(..., 4)``."""
    return matrix_to_quat(sixd_to_matrix(d6))


def expmap_to_matrix(v) -> np.ndarray:
    """Rotation vectors ``(..., 3)`` → matrices ``(..., 3, 3)``."""
    return quat_to_matrix(quat_from_expmap(v))


def align_hemisphere(q, axis: int = 0) -> np.ndarray:
    """Flip signs along ``axis`` so consecutive quaternions have a non-negative dot product.

    Args:
        q: quaternions ``(..., 4)``; ``axis`` indexes a leading dimension (e.g. time).

    Returns:
        The same rotations ``(..., 4)`` with a sign-continuous sequence along ``axis``.
    """
    q = np.moveaxis(_arr(q).copy(), axis, 0)
    for i in range(1, q.shape[0]):
        flip = np.sum(q[i] * q[i - 1], axis=-1, keepdims=True) < 0.0
        q[i] = np.where(flip, -q[i], q[i])
    return np.moveaxis(q, 0, axis)
