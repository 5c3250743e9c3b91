"""The take-off state (``jt_tasks.takeoff.state``): its jumping intention (``v_y``, ``000`` §8), where its
default comes from, and the heading normalisation the run-up's file uses."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest


def test_default_v_y_is_the_jump_clips_liftoff_speed():
    from jt_tasks.takeoff.state import liftoff_vertical_speed
    from toolkit import plugins

    measured = liftoff_vertical_speed("jump")
    assert 1.8 < measured < 2.3  # a standing jump's lift-off, not a run's bounce
    assert liftoff_vertical_speed("run") < 1.0  # the steady run carries no jumping intention
    for task in ("highjump", "obstacle", "longjump"):
        default = plugins.load("task", task).Config().v_y  # the one source of the default
        assert default == pytest.approx(measured, abs=0.01), task


def test_v_y_replaces_only_the_vertical_root_speed():
    from jt_tasks.takeoff.state import facing_velocities, takeoff_state

    feats = {"omega_x": -3.0, "omega_z": 1.0, "v_z": -2.4}
    plain = takeoff_state(feats)
    lifted = takeoff_state(feats, v_y=2.06)
    v0, w0 = facing_velocities(plain.q, plain.qd)
    v1, w1 = facing_velocities(lifted.q, lifted.qd)
    assert abs(v0[1]) < 0.3  # mid-support of a steady run: hardly any vertical speed
    assert v1[1] == pytest.approx(2.06, abs=1e-9)
    np.testing.assert_allclose([v1[0], v1[2]], [v0[0], v0[2]], atol=1e-9)
    np.testing.assert_allclose(w1, w0, atol=1e-9)
    np.testing.assert_array_equal(lifted.q, plain.q)
    np.testing.assert_array_equal(lifted.qd[6:], plain.qd[6:])


def test_normalise_heading_turns_a_state_to_heading_x_above_the_origin():
    from jt_tasks.takeoff.state import facing_velocities, heading_quat, normalise_heading, takeoff_state
    from toolkit.motion import rotations as rot

    ts = takeoff_state({"omega_x": -1.0, "omega_z": 0.5, "v_z": -1.5})
    turn = rot.quat_from_axis_angle(np.array([0.0, 1.0, 0.0]), 0.7)
    q, qd = ts.q.copy(), ts.qd.copy()
    q[:3] = [4.0, q[1], -2.0]
    q[3:7] = rot.quat_multiply(turn, q[3:7])
    qd[:3], qd[3:6] = rot.quat_rotate(turn, qd[:3]), rot.quat_rotate(turn, qd[3:6])
    q2, qd2 = normalise_heading(q, qd)
    assert q2[0] == 0.0 and q2[2] == 0.0 and q2[1] == q[1]
    np.testing.assert_allclose(rot.quat_rotate(heading_quat(q2[3:7]), np.array([1.0, 0.0, 0.0])), [1, 0, 0], atol=1e-9)
    for a, b in zip(facing_velocities(q2, qd2), facing_velocities(q, qd)):
        np.testing.assert_allclose(a, b, atol=1e-9)
    np.testing.assert_array_equal(q2[7:], q[7:])
    np.testing.assert_array_equal(qd2[6:], qd[6:])
