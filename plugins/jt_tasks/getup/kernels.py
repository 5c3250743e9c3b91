"""Compiled per-step pieces of the get-up env (numba): the heading frame and the height map's ray
grid, the link velocities, the joint rotations and the link block of the observation.

Each kernel does, on scalars, what its numpy counterpart does on arrays (``features.heading_yaw``,
``features.heightmap_points``, ``style_features``, ``rotations.quat_to_expmap`` of the link
rotation over a step, ``env.joint_rotations``): the same formulas with the same special cases, to
the last bits or an ulp of them (numpy's matrix products and norms may sum in another order).
None of it feeds the dynamics: observations and rewards only (``tests/.../test_getup_kernels.py``
holds each against its numpy path; the env goldens hold the whole env at 1e-9).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from toolkit.motion.kernels import quat_mul
from toolkit.motion.rotations import EPS, SMALL  # below EPS a norm is zero; below SMALL the log map's series


@njit(cache=True)
def frame(neck: np.ndarray, r_hip: np.ndarray, l_hip: np.ndarray, n: int, spacing: float, span: float,
          fallback: float, starts: np.ndarray, ends: np.ndarray, torso: np.ndarray) -> float:
    """Heading yaw (``features.heading_yaw``) of the neck and hip joints ``(3,)``; fills the height
    map's vertical rays ``starts``/``ends`` ``(n * n, 3)`` (``heightmap_points`` at the hips,
    ``span`` m above and below them) and ``torso`` ``(6,)`` with the unit side and front vectors."""
    sx, sy, sz = r_hip[0] - l_hip[0], r_hip[1] - l_hip[1], r_hip[2] - l_hip[2]
    ns = max(math.sqrt(sx * sx + sy * sy + sz * sz), 1e-12)
    sx, sy, sz = sx / ns, sy / ns, sz / ns
    hx, hy, hz = 0.5 * (r_hip[0] + l_hip[0]), 0.5 * (r_hip[1] + l_hip[1]), 0.5 * (r_hip[2] + l_hip[2])
    ax, ay, az = neck[0] - hx, neck[1] - hy, neck[2] - hz
    fx, fy, fz = ay * sz - az * sy, az * sx - ax * sz, ax * sy - ay * sx  # (neck - hips) x side
    nf = max(math.sqrt(fx * fx + fy * fy + fz * fz), 1e-12)
    torso[0], torso[1], torso[2], torso[3], torso[4], torso[5] = sx, sy, sz, fx / nf, fy / nf, fz / nf
    wx, wz = sz, -sx  # up x side: horizontal, the facing direction when standing
    nw = math.sqrt(wx * wx + wz * wz)
    if nw < fallback:  # on the side: the torso's long axis, projected
        if math.sqrt(ax * ax + az * az) > 1e-6:
            wx, wz = ax, az
        elif nw < 1e-9:
            wx, wz = 1.0, 0.0
    yaw = math.atan2(-wz, wx)
    c, s = math.cos(yaw), math.sin(yaw)
    k = 0
    for i in range(n):
        gx = (i - (n - 1) / 2.0) * spacing
        for j in range(n):
            gz = (j - (n - 1) / 2.0) * spacing
            x, z = gx * c + gz * s + hx, gx * -s + gz * c + hz
            starts[k, 0], starts[k, 1], starts[k, 2] = x, hy + span, z
            ends[k, 0], ends[k, 1], ends[k, 2] = x, hy - span, z
            k += 1
    return yaw


@njit(cache=True)
def angle_to_up(x: float, y: float, z: float) -> float:
    """∠(v, +y) in [0, π] (``features.angle_to_up``)."""
    return math.atan2(math.sqrt(z * z + x * x), y)


@njit(cache=True)
def link_velocities(pos: np.ndarray, orn: np.ndarray, p0: np.ndarray, o0: np.ndarray, dt: float,
                    w: np.ndarray, v: np.ndarray) -> None:
    """Finite-difference link velocities over ``dt``: ``v = (pos - p0) / dt`` and ``w =
    log(orn · conj(o0)) / dt`` ``(n, 3)`` from positions ``(n, 3)`` and quaternions ``(n, 4)``."""
    for i in range(pos.shape[0]):
        for k in range(3):
            v[i, k] = (pos[i, k] - p0[i, k]) / dt
        ax, ay, az, aw = orn[i, 0], orn[i, 1], orn[i, 2], orn[i, 3]
        x, y, z, q = quat_mul(ax, ay, az, aw, -o0[i, 0], -o0[i, 1], -o0[i, 2], o0[i, 3])
        nq = math.sqrt(x * x + y * y + z * z + q * q)
        if nq > EPS:
            x, y, z, q = x / nq, y / nq, z / nq, q / nq
        else:
            x, y, z, q = 0.0, 0.0, 0.0, 1.0
        if q < 0.0:
            x, y, z, q = -x, -y, -z, -q
        s = math.sqrt(x * x + y * y + z * z)
        if s < SMALL:
            scale = (2.0 / q) * (1.0 - s ** 2 / (3.0 * q ** 2))
        else:
            scale = 2.0 * math.atan2(s, q) / s
        w[i, 0], w[i, 1], w[i, 2] = x * scale / dt, y * scale / dt, z * scale / dt


@njit(cache=True)
def joint_rotations(q: np.ndarray, start: np.ndarray, spherical: np.ndarray, axes: np.ndarray,
                    out: np.ndarray) -> None:
    """Each joint's rotation ``out`` ``(n_joints, 4)`` from the generalised position ``q``: a
    spherical joint's normalised quaternion at ``q[start:start + 4]``, a revolute joint's rotation
    by ``q[start]`` about its unit axis ``axes`` ``(n_joints, 3)`` (``env.joint_rotations``)."""
    for j in range(start.shape[0]):
        a = start[j]
        if spherical[j]:
            x, y, z, w = q[a], q[a + 1], q[a + 2], q[a + 3]
            n = math.sqrt(x * x + y * y + z * z + w * w)
            if n > EPS:
                out[j, 0], out[j, 1], out[j, 2], out[j, 3] = x / n, y / n, z / n, w / n
            else:
                out[j, 0], out[j, 1], out[j, 2], out[j, 3] = 0.0, 0.0, 0.0, 1.0
        else:
            ux, uy, uz = axes[j, 0], axes[j, 1], axes[j, 2]
            n = max(math.sqrt(ux * ux + uy * uy + uz * uz), EPS)
            half = 0.5 * q[a]
            sh = math.sin(half)
            out[j, 0], out[j, 1], out[j, 2], out[j, 3] = ux / n * sh, uy / n * sh, uz / n * sh, math.cos(half)


@njit(cache=True)
def observe_links(pos: np.ndarray, orn: np.ndarray, w: np.ndarray, v: np.ndarray, yaw: float,
                  out: np.ndarray) -> None:
    """The observation's link block ``out`` ``(13 n,)`` in the heading frame of ``yaw``: the link
    quaternions (``w >= 0``) ``(n, 4)``, positions relative to the root, angular and linear
    velocities ``(n, 3)`` each, as ``GetupEnv.observe`` lays them out."""
    n = pos.shape[0]
    c, s = math.cos(yaw), math.sin(yaw)
    hs, hc = math.sin(0.5 * yaw), math.cos(0.5 * yaw)  # the heading quaternion (0, hs, 0, hc)
    for i in range(n):
        bx, by, bz, bw = orn[i, 0], orn[i, 1], orn[i, 2], orn[i, 3]
        x = hc * bx + -hs * bz
        y = hc * by + bw * -hs
        z = hc * bz + hs * bx
        q = hc * bw + hs * by
        if q < 0.0:
            x, y, z, q = -x, -y, -z, -q
        out[4 * i], out[4 * i + 1], out[4 * i + 2], out[4 * i + 3] = x, y, z, q
        o = 4 * n + 3 * i
        px, py, pz = pos[i, 0] - pos[0, 0], pos[i, 1] - pos[0, 1], pos[i, 2] - pos[0, 2]
        out[o], out[o + 1], out[o + 2] = c * px - s * pz, py, s * px + c * pz
        o += 3 * n
        out[o], out[o + 1], out[o + 2] = c * w[i, 0] - s * w[i, 2], w[i, 1], s * w[i, 0] + c * w[i, 2]
        o += 3 * n
        out[o], out[o + 1], out[o + 2] = c * v[i, 0] - s * v[i, 2], v[i, 1], s * v[i, 0] + c * v[i, 2]
