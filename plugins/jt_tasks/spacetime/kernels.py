"""Compiled per-step arithmetic of the spacetime env (numba, cached on disk): the reference at a
clip time, the observation and the bounds' difference vector.

Each kernel does, on scalars, the operations the numpy code it replaces did, in the same order:
numpy's elementwise products and sums, its 3- and 4-element reductions (sequential) and
``sin`` / ``cos`` (the C library's, as numpy's here) give the same bits, so the reference state an
episode starts from is unchanged to the last digit (``test_spacetime_env_golden``). ``atan2``
(the bounds' angles) may differ from numpy's SIMD ``arctan2`` in the last digit; nothing it feeds
reaches the dynamics.

Quaternions are ``(x, y, z, w)``, y-up world; the heading is a turn about +y (``reference``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from toolkit.motion.kernels import quat_mul
from toolkit.motion.rotations import EPS, SMALL


@njit(cache=True)
def heading_inverse(qx: float, qy: float, qz: float, qw: float, axis_z: bool) -> tuple:
    """The inverse ``(x, y, z, w)`` of ``reference.heading_quat`` of the root quaternion."""
    if axis_z:
        a0, a1, a2 = 0.0, 0.0, 1.0
    else:
        a0, a1, a2 = 1.0, 0.0, 0.0
    # quat_rotate(q, a): t = 2 (u x a), a + w t + u x t
    tx, ty, tz = 2.0 * (qy * a2 - qz * a1), 2.0 * (qz * a0 - qx * a2), 2.0 * (qx * a1 - qy * a0)
    fx = a0 + qw * tx + (qy * tz - qz * ty)
    fz = a2 + qw * tz + (qx * ty - qy * tx)
    yaw = math.atan2(-fz, fx) - math.atan2(-a2, a0)
    half = 0.5 * yaw
    sn, cs = math.sin(half), math.cos(half)
    return -(0.0 * sn), -(1.0 * sn), -(0.0 * sn), cs


@njit(cache=True)
def _rotate(x: float, y: float, z: float, w: float, vx: float, vy: float, vz: float) -> tuple:
    tx, ty, tz = 2.0 * (y * vz - z * vy), 2.0 * (z * vx - x * vz), 2.0 * (x * vy - y * vx)
    return vx + w * tx + (y * tz - z * ty), vy + w * ty + (z * tx - x * tz), vz + w * tz + (x * ty - y * tx)


@njit(cache=True)
def sample(i: int, f: float, held: bool, cos_a: float, sin_a: float, p0: np.ndarray, origin: np.ndarray,
           root_pos: np.ndarray, joints: np.ndarray, vel: np.ndarray, com: np.ndarray, ee: np.ndarray,
           q0: np.ndarray, log: np.ndarray, sph: np.ndarray, q_out: np.ndarray, qd_out: np.ndarray,
           com_out: np.ndarray, ee_out: np.ndarray) -> None:
    """The reference between frames ``i`` and ``i + 1`` at fraction ``f``, moved into its cycle.

    The cycle's ground-plane motion (``SpacetimeReference``): horizontal positions ``x`` become
    ``R (x - p0) + origin``, the root rotation ``R q`` and the root velocities ``R v``, with ``R``
    the turn about +y of cosine ``cos_a`` and sine ``sin_a`` (1, 0 in the first cycle: positions
    only shifted by ``origin - p0``); joints and the heading-frame end effectors are unchanged.

    Args:
        p0: the first frame's root on the ground plane ``(3,)``; origin: its place in this cycle.
        root_pos: ``(n_frames, 3)``; joints: ``(n_frames, n_joint_q)``; vel: ``(n_frames, n_dof)``;
            com: ``(n_frames, 3)``; ee: ``(n_frames, 4, 3)`` (heading frame).
        q0, log: the slerp tables ``(n_frames - 1, 1 + n_spherical, 4)`` / ``(..., 3)`` (root first).
        sph: ``(n_spherical, 4)`` quaternion columns of the spherical joints in ``joints``.
        q_out: ``(3 + 4 + n_joint_q,)``; qd_out: ``(n_dof,)``; com_out: ``(3,)``; ee_out: ``(4, 3)``.
    """
    g = 1 - f
    px = g * root_pos[i, 0] + f * root_pos[i + 1, 0] - p0[0]
    pz = g * root_pos[i, 2] + f * root_pos[i + 1, 2] - p0[2]
    q_out[0] = cos_a * px + sin_a * pz + origin[0]
    q_out[1] = g * root_pos[i, 1] + f * root_pos[i + 1, 1]
    q_out[2] = -sin_a * px + cos_a * pz + origin[2]
    cx = g * com[i, 0] + f * com[i + 1, 0] - p0[0]
    cz = g * com[i, 2] + f * com[i + 1, 2] - p0[2]
    com_out[0] = cos_a * cx + sin_a * cz + origin[0]
    com_out[1] = g * com[i, 1] + f * com[i + 1, 1]
    com_out[2] = -sin_a * cx + cos_a * cz + origin[2]
    nj = joints.shape[1]
    for j in range(nj):
        q_out[7 + j] = g * joints[i, j] + f * joints[i + 1, j]
    # the turn's half-angle quaternion (0, sh, 0, ch) from cos / sin of the angle
    ch = math.sqrt(max(0.5 * (1.0 + cos_a), 0.0))
    sh = 0.0 if ch == 0.0 else 0.5 * sin_a / ch
    if ch == 0.0:
        sh = 1.0
    for r in range(q0.shape[1]):
        v0, v1, v2 = log[i, r, 0] * f, log[i, r, 1] * f, log[i, r, 2] * f
        theta = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
        if theta < SMALL:
            scale = 0.5 - theta * theta / 48.0  # numpy squares by multiplying
        else:
            scale = math.sin(0.5 * theta) / theta
        bx, by, bz, bw = v0 * scale, v1 * scale, v2 * scale, math.cos(0.5 * theta)
        x, y, z, w = quat_mul(q0[i, r, 0], q0[i, r, 1], q0[i, r, 2], q0[i, r, 3], bx, by, bz, bw)
        n = math.sqrt(x * x + y * y + z * z + w * w)
        if n > EPS:
            m = max(n, EPS)
            x, y, z, w = x / m, y / m, z / m, w / m
        else:
            x, y, z, w = 0.0, 0.0, 0.0, 1.0
        if r == 0:
            if sin_a != 0.0:  # (0, sh, 0, ch) * (x, y, z, w)
                x, y, z, w = ch * x + sh * z, ch * y + sh * w, ch * z - sh * x, ch * w - sh * y
            q_out[3], q_out[4], q_out[5], q_out[6] = x, y, z, w
        else:
            c = sph[r - 1]
            q_out[7 + c[0]], q_out[7 + c[1]], q_out[7 + c[2]], q_out[7 + c[3]] = x, y, z, w
    for j in range(qd_out.shape[0]):
        qd_out[j] = 0.0 if held else g * vel[i, j] + f * vel[i + 1, j]
    if sin_a != 0.0:
        for b in range(2):
            vx, vz = qd_out[3 * b], qd_out[3 * b + 2]
            qd_out[3 * b], qd_out[3 * b + 2] = cos_a * vx + sin_a * vz, -sin_a * vx + cos_a * vz
    for e in range(4):
        for d in range(3):
            ee_out[e, d] = g * ee[i, e, d] + f * ee[i + 1, e, d]


@njit(cache=True)
def _finite(x: float) -> float:
    return x if math.isfinite(x) else 0.0


@njit(cache=True)
def observe(q: np.ndarray, qd: np.ndarray, pos: np.ndarray, orn: np.ndarray, lin: np.ndarray, ang: np.ndarray,
            phase: float, axis_z: bool, root_world: bool, fy: float, fw: float, out: np.ndarray) -> None:
    """The observation (``SpacetimeEnv.observe``) into ``out`` float32: phase, root height, link
    CoMs ``pos`` ``(n, 3)`` relative to the ground-projected root and orientations ``orn``
    ``(n, 4)`` (w >= 0) in the heading frame, root velocities in the heading frame, then either the
    joint velocities (``lin`` empty: ``(2 + 7 n + n_dof,)``) or every other link's CoM linear and
    angular velocity ``lin``, ``ang`` ``(n, 3)`` (world; row 0, the root, unused) in the heading
    frame (``(2 + 13 n,)``, 002 §4.1); NaN and inf as 0. With ``root_world`` the root's orientation
    (link 0) is taken in the frame ``(0, fy, 0, fw)`` (the inverse of the reference cycle's yaw;
    the world frame when cycles do not turn) instead of the heading frame (002 §4.1)."""
    ix, iy, iz, iw = heading_inverse(q[3], q[4], q[5], q[6], axis_z)
    n = pos.shape[0]
    out[0], out[1] = _finite(phase), _finite(q[1])
    rx, rz = q[0], q[2]
    for l in range(n):
        px, py, pz = _rotate(ix, iy, iz, iw, pos[l, 0] - rx, pos[l, 1] - 0.0, pos[l, 2] - rz)
        out[2 + 3 * l], out[3 + 3 * l], out[4 + 3 * l] = _finite(px), _finite(py), _finite(pz)
    o = 2 + 3 * n
    for l in range(n):
        if l == 0 and root_world:
            x, y, z, w = quat_mul(0.0, fy, 0.0, fw, orn[l, 0], orn[l, 1], orn[l, 2], orn[l, 3])
        else:
            x, y, z, w = quat_mul(ix, iy, iz, iw, orn[l, 0], orn[l, 1], orn[l, 2], orn[l, 3])
        if w < 0.0:
            x, y, z, w = -x, -y, -z, -w
        out[o + 4 * l], out[o + 4 * l + 1], out[o + 4 * l + 2], out[o + 4 * l + 3] = \
            _finite(x), _finite(y), _finite(z), _finite(w)
    o += 4 * n
    for b in range(2):
        vx, vy, vz = _rotate(ix, iy, iz, iw, qd[3 * b], qd[3 * b + 1], qd[3 * b + 2])
        out[o + 3 * b], out[o + 3 * b + 1], out[o + 3 * b + 2] = _finite(vx), _finite(vy), _finite(vz)
    o += 6
    if lin.shape[0] == 0:
        for j in range(6, qd.shape[0]):
            out[o + j - 6] = _finite(qd[j])
        return
    for l in range(1, n):
        vx, vy, vz = _rotate(ix, iy, iz, iw, lin[l, 0], lin[l, 1], lin[l, 2])
        wx, wy, wz = _rotate(ix, iy, iz, iw, ang[l, 0], ang[l, 1], ang[l, 2])
        k = o + 6 * (l - 1)
        out[k], out[k + 1], out[k + 2] = _finite(vx), _finite(vy), _finite(vz)
        out[k + 3], out[k + 4], out[k + 5] = _finite(wx), _finite(wy), _finite(wz)


@njit(cache=True)
def difference(q: np.ndarray, com: np.ndarray, ee_world: np.ndarray, ref_q: np.ndarray, ref_com: np.ndarray,
               ref_ee: np.ndarray, axis_z: bool, cols: np.ndarray, at: np.ndarray, rev_at: np.ndarray,
               rev_cols: np.ndarray, out: np.ndarray) -> None:
    """The bounds' difference vector (``bounds.difference``) into ``out`` ``(n_channels,)`` (zeros: the
    fixed joints' channels are left as they are).

    Args:
        q, com: the character's pose ``(n_q,)`` and CoM ``(3,)``; ee_world: its end effectors ``(4, 3)``
            (world; put in its heading frame here); ref_q, ref_com, ref_ee: the reference's (its end
            effectors already in its heading frame).
        cols, at, rev_at, rev_cols: ``bounds._angle_columns``.
    """
    for d in range(3):
        out[d] = abs(com[d] - ref_com[d])
    for r in range(cols.shape[0]):
        c = cols[r]
        x, y, z, w = quat_mul(-q[c[0]], -q[c[1]], -q[c[2]], q[c[3]], ref_q[c[0]], ref_q[c[1]], ref_q[c[2]], ref_q[c[3]])
        out[at[r]] = 2.0 * math.atan2(math.sqrt(x * x + y * y + z * z), abs(w))
    for r in range(rev_at.shape[0]):
        out[rev_at[r]] = abs(q[rev_cols[r]] - ref_q[rev_cols[r]])
    ix, iy, iz, iw = heading_inverse(q[3], q[4], q[5], q[6], axis_z)
    m = out.shape[0] - 4
    for e in range(4):
        px, py, pz = _rotate(ix, iy, iz, iw, ee_world[e, 0] - q[0], ee_world[e, 1] - 0.0, ee_world[e, 2] - q[2])
        dx, dy, dz = px - ref_ee[e, 0], py - ref_ee[e, 1], pz - ref_ee[e, 2]
        out[m + e] = math.sqrt(dx * dx + dy * dy + dz * dz)
