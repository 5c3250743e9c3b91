"""Strategy features on constructed crossings (000 §6.1.4)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from jt_tasks.jumping.features import CrossingTracker, angle_distance, suite_orientation, up_angle
from toolkit.motion import rotations as rot


def test_up_angle_of_known_orientations():
    assert up_angle(np.array([0, 0, 0, 1.0])) == pytest.approx(0.0)
    assert up_angle(rot.quat_from_axis_angle(np.array([1.0, 0, 0]), math.pi)) == pytest.approx(math.pi)
    assert up_angle(rot.quat_from_axis_angle(np.array([0, 0, 1.0]), 0.7)) == pytest.approx(0.7)
    # a turn about up does not change it
    assert up_angle(rot.quat_from_axis_angle(np.array([0, 1.0, 0]), 2.0)) == pytest.approx(0.0, abs=1e-9)


def test_crossing_interpolates_the_orientation_at_the_plane():
    tr = CrossingTracker()
    q0 = np.array([0, 0, 0, 1.0])
    q1 = rot.quat_from_axis_angle(np.array([1.0, 0, 0]), 1.0)
    assert not tr.update(0.0, -0.3, q0)
    assert not tr.update(0.1, -0.1, q0)
    assert tr.update(0.2, 0.3, q1)  # zero crossing at 1/4 of the way from -0.1 to 0.3
    assert tr.time == pytest.approx(0.125)
    assert tr.stage1() == pytest.approx(0.25)
    assert not tr.update(0.3, -0.1, q0) and tr.stage1() == pytest.approx(0.25)  # first crossing only


def test_no_crossing_no_feature():
    tr = CrossingTracker()
    tr.update(0.0, -0.5, np.array([0, 0, 0, 1.0]))
    tr.update(0.1, -0.2, np.array([0, 0, 0, 1.0]))
    assert not tr.crossed and math.isnan(tr.stage1())
    assert np.all(np.isnan(tr.stage2(np.eye(3))))


def test_stage2_feature_is_independent_of_the_approach_angle():
    # the same body pose relative to two suites turned by different approach angles
    feats = []
    for a in (0.0, 1.2):
        R = rot.quat_to_matrix(rot.quat_from_axis_angle(np.array([0, 1.0, 0]), a))
        q_world = rot.quat_multiply(rot.matrix_to_quat(R), rot.quat_from_axis_angle(np.array([1.0, 0, 0]), 0.4))
        feats.append(suite_orientation(q_world, R))
    np.testing.assert_allclose(feats[0], feats[1], atol=1e-9)


def test_angle_distance():
    assert angle_distance([0.2], [3.0]) == pytest.approx(2.8)
    assert float(angle_distance([0.0], [math.pi])) == pytest.approx(math.pi)


def test_update_many_equals_update_one_by_one():
    """The vectorised feed finds the same crossing (time, orientation) as the loop, from any split."""
    from jt_tasks.jumping.features import CrossingTracker

    rng = np.random.default_rng(3)
    t = np.arange(40) / 600.0
    d = np.linspace(-0.2, 0.3, 40) + 0.02 * np.sin(np.arange(40))
    q = rng.normal(size=(40, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    one = CrossingTracker()
    for row in zip(t, d, q):
        one.update(*row)
    for split in (1, 7, 23, 39):
        many = CrossingTracker()
        many.update_many(t[:split], d[:split], q[:split])
        many.update_many(t[split:], d[split:], q[split:])
        assert many.crossed == one.crossed and many.time == one.time
        np.testing.assert_array_equal(many.q_root, one.q_root)
        assert many._prev[0] == one._prev[0]


def test_a_landing_before_the_crossing_takes_the_feature_there():
    """A jump that lands on the mat reaching over, with the CoM still short of the plane, gets its
    feature at the landing instead of none (its strategy is still a strategy)."""
    from jt_tasks.jumping.features import CrossingTracker

    tr = CrossingTracker()
    tr.update(0.0, -0.3, np.array([0.0, 0.0, 0.0, 1.0]))
    tr.update(0.1, -0.1, np.array([0.0, 0.0, 0.0, 1.0]))
    assert not tr.crossed and math.isnan(tr.stage1())
    tilt = np.array([np.sin(0.25), 0.0, 0.0, np.cos(0.25)])  # 0.5 rad about x
    tr.land(0.12, tilt)
    assert tr.crossed and tr.at_landing and tr.stage1() == pytest.approx(0.5, abs=1e-9)
    tr.land(0.2, np.array([0.0, 0.0, 0.0, 1.0]))  # only the first counts
    assert tr.stage1() == pytest.approx(0.5, abs=1e-9)
