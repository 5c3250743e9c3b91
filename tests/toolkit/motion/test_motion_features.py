"""Pose features (000 §4.2) and get-up conditions (003 §3.5) on real clips and hand-built poses."""

from __future__ import annotations

import numpy as np
import pytest

from toolkit.motion import rotations as rot
from toolkit.motion.clips import load_humanoid_clips
from toolkit.motion.features import (
    FeatureLayout,
    clip_features,
    feature_layout,
    features_to_joints,
    getup_conditions,
    pose_features,
)
from toolkit.motion.kinematics import forward_kinematics
from toolkit.motion.skeletons import HUMANOID


@pytest.fixture(scope="module")
def clips():
    return {c.name: c for c in load_humanoid_clips(["walk", "getup_faceup", "getup_facedown", "cartwheel"])}


def test_layout():
    lay = feature_layout(HUMANOID)
    kinds = [b.kind for b in lay.blocks]
    # 11 moving joint origins + 14 link COMs (the root link's is constant) + 12 joints in 6D
    assert kinds.count("joint_pos") == 11 and kinds.count("link_com") == 14 and kinds.count("rot6d") == 12
    assert lay.size == 11 * 3 + 14 * 3 + 12 * 6 == 147
    names = {b.name for b in lay.blocks if b.kind == "joint_pos"}
    assert "chest" not in names and "right_hip" not in names and "right_wrist" in names
    assert FeatureLayout.from_json(lay.to_json()) == lay
    assert len(lay.columns("rot6d")) == 72
    assert lay.block("left_knee", "rot6d").stop - lay.block("left_knee", "rot6d").start == 6


def test_features_are_in_the_root_frame(clips):
    c = clips["cartwheel"]
    f, lay = pose_features(HUMANOID, c.root_pos, c.root_rot, c.joints)
    # a global rigid motion of the whole body changes nothing
    g = rot.quat_from_expmap([0.3, -1.1, 0.7])
    f2, _ = pose_features(HUMANOID, rot.quat_rotate(g, c.root_pos) + [5.0, -2.0, 1.0],
                          rot.quat_multiply(g, c.root_rot), c.joints)  # fmt: skip
    np.testing.assert_allclose(f2, f, atol=2e-6)  # PyBullet's link states carry ~1e-7 rounding
    # at the rest pose, positions are the URDF offsets (scaled): the right wrist hangs below the shoulder
    rest, _ = pose_features(HUMANOID, [[0, 0.9, 0]], [[0, 0, 0, 1]], HUMANOID.rest_joints((1,)))
    np.testing.assert_allclose(rest[0, lay.block("right_ankle", "joint_pos")], [0, -0.831416, 0.084887], atol=1e-5)
    np.testing.assert_allclose(rest[0, lay.block("neck", "joint_pos")], [0, 0.460045, 0], atol=1e-5)
    np.testing.assert_allclose(rest[0, lay.columns("rot6d")], np.tile([1, 0, 0, 0, 1, 0], 12))


def test_rotation_blocks_decode_back(clips):
    c = clips["walk"]
    f, lay = pose_features(HUMANOID, c.root_pos, c.root_rot, c.joints)
    np.testing.assert_allclose(f[:, lay.block("chest", "rot6d")], rot.quat_to_6d(c.joint("chest")), atol=1e-12)
    back = features_to_joints(f, lay)
    for j, s in zip(HUMANOID.joints, HUMANOID.q_slices.values()):
        if j.kind == "spherical":
            assert np.all(rot.quat_angle(back[:, s], c.joints[:, s]) < 1e-9)
        else:
            np.testing.assert_allclose(back[:, s], c.joints[:, s], atol=1e-12)
    # noisy 6D (as a decoder outputs) still decodes to valid joints near the truth
    noisy = f + np.random.default_rng(0).normal(scale=1e-3, size=f.shape)
    b2 = features_to_joints(noisy, lay)
    assert np.all(rot.quat_angle(b2[:, HUMANOID.q_slices["neck"]], c.joint("neck")) < 1e-2)


def test_mirrored_features_are_reflected(clips):
    c = clips["walk"]
    f, lay = pose_features(HUMANOID, c.root_pos, c.root_rot, c.joints)
    m = c.mirror()
    fm, _ = pose_features(HUMANOID, m.root_pos, m.root_rot, m.joints)
    for b in lay.blocks:
        if b.kind == "rot6d":
            continue
        other = b.name.replace("right_", "@").replace("left_", "right_").replace("@", "left_")
        np.testing.assert_allclose(fm[:, b.start : b.stop], f[:, lay.block(other, b.kind)] * [1, 1, -1], atol=1e-9)


def _conditions_of(root_rot, root_pos=(0.0, 0.9, 0.0)):
    k = forward_kinematics(HUMANOID, [root_pos], [root_rot], HUMANOID.rest_joints((1,)))
    return getup_conditions(HUMANOID, k)[0]


def test_conditions_on_hand_built_poses():
    h, side, front = _conditions_of([0, 0, 0, 1])  # standing: side and front horizontal
    assert h == pytest.approx(0.9 + 0.460045, abs=1e-5)
    assert side == pytest.approx(np.pi / 2, abs=1e-9) and front == pytest.approx(np.pi / 2, abs=1e-9)
    # lying on the back: rotate +90 deg about the lateral axis z (front x -> up y)
    _, side, front = _conditions_of(rot.quat_from_axis_angle([0, 0, 1], np.pi / 2), (0, 0.1, 0))
    assert front == pytest.approx(0.0, abs=1e-7) and side == pytest.approx(np.pi / 2, abs=1e-9)
    # lying face down
    _, _, front = _conditions_of(rot.quat_from_axis_angle([0, 0, 1], -np.pi / 2), (0, 0.1, 0))
    assert front == pytest.approx(np.pi, abs=1e-7)
    # lying on the right side: rotate about the forward axis x so that right (+z) points down (-y)
    _, side, front = _conditions_of(rot.quat_from_axis_angle([1, 0, 0], np.pi / 2), (0, 0.1, 0))
    assert side == pytest.approx(np.pi, abs=1e-7) and front == pytest.approx(np.pi / 2, abs=1e-9)


def test_conditions_on_getup_clips(clips):
    _, up, _ = clip_features(clips["getup_faceup"])
    _, down, _ = clip_features(clips["getup_facedown"])
    assert up[0, 2] < 0.3 and down[0, 2] > np.pi - 0.5  # start: face up / face down
    for c in (up, down):
        assert c[0, 0] < 0.4 and c[-1, 0] > 1.2  # from the floor to standing (neck base height, m)
        assert abs(c[-1, 1] - np.pi / 2) < 0.3 and abs(c[-1, 2] - np.pi / 2) < 0.3
    assert np.all((up[:, 1:] >= 0) & (up[:, 1:] <= np.pi))


def test_conditions_under_mirroring(clips):
    c = clips["cartwheel"]
    _, a, _ = clip_features(c)
    _, b, _ = clip_features(c.mirror())
    # the side vector flips across the sagittal plane, the front vector does not
    np.testing.assert_allclose(b[:, 0], a[:, 0], atol=1e-9)
    np.testing.assert_allclose(b[:, 1], np.pi - a[:, 1], atol=1e-7)
    np.testing.assert_allclose(b[:, 2], a[:, 2], atol=1e-7)
    _, g, _ = clip_features(c, ground_height=0.25)
    np.testing.assert_allclose(g[:, 0], a[:, 0] - 0.25)
