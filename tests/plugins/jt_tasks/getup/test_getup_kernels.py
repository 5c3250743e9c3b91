"""The get-up env's compiled pieces against the numpy paths they replace (``getup.kernels``).

Each kernel does what its numpy counterpart does; they are held here on random inputs and on
the special cases (a torso on its side, a zero-angle revolute joint, a link that did not turn).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from jt_tasks.getup import env as E
from jt_tasks.getup import features as F
from jt_tasks.getup import kernels as K
from toolkit.motion import rotations as rot

TOL = 1e-12


def random_quats(rng: np.random.Generator, n: int) -> np.ndarray:
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def torsos(rng: np.random.Generator):
    """Random neck/hip triples, plus a torso lying on its side (side vector ~ up)."""
    for _ in range(50):
        hips = rng.normal(size=3) + [0.0, 0.5, 0.0]
        side = rng.normal(size=3)
        side *= 0.08 / np.linalg.norm(side)
        yield hips + rng.normal(size=3) * 0.4, hips + side, hips - side
    yield np.array([0.4, 0.2, 0.1]), np.array([0.0, 0.28, 0.0]), np.array([0.0, 0.12, 0.0])
    yield np.array([0.0, 0.2, 0.0]), np.array([0.0, 0.28, 0.0]), np.array([0.0, 0.12, 0.0])  # neck over hips


def test_frame_is_heading_yaw_heightmap_points_and_torso_vectors():
    rng = np.random.default_rng(0)
    for neck, r_hip, l_hip in torsos(rng):
        starts, ends, torso = np.empty((25, 3)), np.empty((25, 3)), np.empty(6)
        yaw = K.frame(neck, r_hip, l_hip, 5, 0.25, 5.0, F.SIDE_FALLBACK, starts, ends, torso)
        want = F.heading_yaw(neck, r_hip, l_hip)
        assert yaw == pytest.approx(want, abs=TOL)
        hips = 0.5 * (r_hip + l_hip)
        pts = F.heightmap_points(hips, want, 5, 0.25)
        np.testing.assert_allclose(starts[:, [0, 2]], pts[:, [0, 2]], rtol=0, atol=TOL)
        np.testing.assert_allclose(ends[:, [0, 2]], pts[:, [0, 2]], rtol=0, atol=TOL)
        assert np.all(starts[:, 1] == hips[1] + 5.0) and np.all(ends[:, 1] == hips[1] - 5.0)
        side, front = F.torso_vectors(neck, r_hip, l_hip)
        np.testing.assert_allclose(torso, np.concatenate([side, front]), rtol=0, atol=TOL)
        feats = F.style_features(neck, r_hip, l_hip, 0.0)
        assert K.angle_to_up(*side) == pytest.approx(feats[1], abs=TOL)
        assert K.angle_to_up(*front) == pytest.approx(feats[2], abs=TOL)


def test_link_velocities_are_the_finite_differences():
    rng = np.random.default_rng(1)
    pos, p0 = rng.normal(size=(16, 3)), rng.normal(size=(16, 3))
    o0 = random_quats(rng, 16)
    turn = rot.quat_from_axis_angle(rng.normal(size=(16, 3)), rng.uniform(-3.0, 3.0, 16))
    turn[3] = [0.0, 0.0, 0.0, 1.0]  # a link that did not turn
    turn[4] = rot.quat_from_axis_angle(np.array([1.0, 0.0, 0.0]), 1e-8)  # the log map's series
    orn = rot.quat_multiply(turn, o0)
    orn[5] *= -1.0  # the other cover: the same rotation
    dt = 1.0 / 30.0
    w, v = np.empty((16, 3)), np.empty((16, 3))
    K.link_velocities(pos, orn, p0, o0, dt, w, v)
    np.testing.assert_allclose(v, (pos - p0) / dt, rtol=0, atol=TOL)
    want = rot.quat_to_expmap(rot.quat_multiply(orn, rot.quat_conjugate(o0))) / dt
    np.testing.assert_allclose(w, want, rtol=0, atol=1e-10)  # rad/s: 30 × the angle's ulps
    assert np.all(w[3] == 0.0)


def test_joint_rotations_match_the_numpy_path():
    from toolkit.motion.skeletons import HUMANOID

    rng = np.random.default_rng(2)
    starts, spherical, axes = E.joint_layout()
    assert len(starts) == len(HUMANOID.joints) and spherical.any() and not spherical.all()
    for k in range(20):
        q = rng.normal(size=7 + max(s.stop for s in HUMANOID.q_slices.values()))
        if k == 0:
            q[7:] = 0.0  # zero quaternions (identity) and zero angles
        out = np.empty((len(starts), 4))
        K.joint_rotations(q, starts, spherical, axes, out)
        np.testing.assert_allclose(out, E.joint_rotations(q), rtol=0, atol=TOL)


def test_observe_links_is_the_heading_frame_block():
    rng = np.random.default_rng(3)
    n = 16
    pos, w, v = rng.normal(size=(n, 3)), rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    orn = random_quats(rng, n)
    for yaw in (0.0, 0.7, -2.9, math.pi):
        out = np.empty(13 * n)
        K.observe_links(pos, orn, w, v, yaw, out)
        R = F.heading_rotation(yaw)
        hq = rot.quat_from_axis_angle(np.array([0.0, 1.0, 0.0]), yaw)
        q_local = rot.quat_canonical(rot.quat_multiply(rot.quat_conjugate(hq)[None, :], orn))
        want = np.concatenate([q_local.ravel(), ((pos - pos[0]) @ R.T).ravel(), (w @ R.T).ravel(),
                               (v @ R.T).ravel()])
        np.testing.assert_allclose(out, want, rtol=0, atol=TOL)
        assert np.all(out[3:4 * n:4] >= 0.0)
