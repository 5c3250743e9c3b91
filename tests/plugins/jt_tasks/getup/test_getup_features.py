"""Style features (h, θx, θz) and the heading frame of any state (003 §3.1, §4.2, Fig. 4)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from jt_tasks.getup import features as F

# a standing torso facing +x (right = +z): neck above the hips
NECK, RHIP, LHIP = np.array([0.0, 1.3, 0.0]), np.array([0.0, 0.9, 0.08]), np.array([0.0, 0.9, -0.08])


def yaw_rot(psi: float) -> np.ndarray:
    c, s = math.cos(psi), math.sin(psi)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])  # R_y(psi)


def about_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def test_standing_supine_prone_synthetic():
    h, tx, tz = F.style_features(NECK, RHIP, LHIP, 0.0)
    assert (h, tx, tz) == pytest.approx((1.3, math.pi / 2, math.pi / 2))
    # lie on the back: rotate the standing body by +90° about z (front +x -> up)
    R = about_z(math.pi / 2)
    sup = [R @ p + [0, 0.1, 0] for p in (NECK, RHIP, LHIP)]
    h, tx, tz = F.style_features(*sup, 0.0)
    assert tz == pytest.approx(0.0, abs=1e-9) and tx == pytest.approx(math.pi / 2)
    R = about_z(-math.pi / 2)  # on the belly
    pro = [R @ p + [0, 1.0, 0] for p in (NECK, RHIP, LHIP)]
    assert F.style_features(*pro, 0.0)[2] == pytest.approx(math.pi, abs=1e-9)
    # h is against the given mean terrain height
    assert F.style_features(NECK, RHIP, LHIP, 0.25)[0] == pytest.approx(1.05)


def test_clip_poses_standing_and_lying():
    """jt's humanoid and clips (standing h 1.33-1.37 m above the ground a frame rests on, facedown start θz 157°, faceup 5°)."""
    from jt_tasks.getup.curves import clip_feature_track

    _, down = clip_feature_track("getup_facedown")
    _, up = clip_feature_track("getup_faceup")
    for end in (down[-1], up[-1]):
        assert 1.30 < end[0] < 1.40 and abs(end[1] - math.pi / 2) < 0.15 and abs(end[2] - math.pi / 2) < 0.2
    assert math.degrees(down[0, 2]) == pytest.approx(157.0, abs=1.0)
    assert math.degrees(up[0, 2]) == pytest.approx(5.2, abs=1.0)
    # mirroring flips the side vector about the sagittal plane: θx -> π - θx, θz unchanged
    _, mir = clip_feature_track("getup_facedown", True)
    np.testing.assert_allclose(mir[:, 1], math.pi - down[:, 1], atol=1e-6)
    np.testing.assert_allclose(mir[:, [0, 2]], down[:, [0, 2]], atol=1e-6)


def test_heading_follows_yaw_standing_and_lying():
    for psi in (0.0, 0.7, -2.5, 3.0):
        R = yaw_rot(psi)
        yaw = F.heading_yaw(R @ NECK, R @ RHIP, R @ LHIP)
        assert math.remainder(yaw - psi, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)
        L = R @ about_z(math.pi / 2)  # supine, turned by psi: still a defined, turning heading
        y2 = F.heading_yaw(L @ NECK, L @ RHIP, L @ LHIP)
        assert math.remainder(y2 - psi, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)


def test_heading_on_the_side_falls_back_to_the_torso_axis():
    # lying on the right side: side vector points down, torso along +x
    side_pose = [np.array([0.4, 0.15, 0.0]), np.array([0.0, 0.07, 0.0]), np.array([0.0, 0.23, 0.0])]
    assert F.heading_yaw(*side_pose) == pytest.approx(0.0, abs=1e-9)
    # heightmap grid: 5 x 5, 0.25 m, centred, turned with the heading
    pts = F.heightmap_points(np.array([1.0, 0.5, 2.0]), math.pi / 2)
    assert pts.shape == (25, 3)
    np.testing.assert_allclose(pts.mean(axis=0), [1.0, 0.5, 2.0], atol=1e-12)
    # first point: local (-0.5, -0.5) turned by +90° about y: local x -> world -z, local z -> world +x
    np.testing.assert_allclose(pts[0], [1.0 - 0.5, 0.5, 2.0 + 0.5], atol=1e-12)


def test_measure_on_the_simulator_standing():
    """The sim state of the clip's last (standing) frame on flat ground: (≈1.3 m, ≈π/2, ≈π/2);
    the height map is the hip height everywhere."""
    from getup_helpers import standing_sim

    sim = standing_sim()
    try:
        m = F.measure(sim)
        h, tx, tz = m["features"]
        assert 1.25 < h < 1.40 and abs(tx - math.pi / 2) < 0.15 and abs(tz - math.pi / 2) < 0.25
        hips = 0.5 * (m["r_hip"] + m["l_hip"])
        np.testing.assert_allclose(m["heightmap"], hips[1], atol=1e-6)
        np.testing.assert_allclose(m["ground"], 0.0, atol=1e-6)
    finally:
        sim.close()
