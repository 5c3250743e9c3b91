"""The reference motion: any clip, any phase, the clip's own heights, cycles that carry on the
clip's turn, seam-free velocities, hold."""

from __future__ import annotations

import numpy as np
import pytest

from jt_tasks.spacetime.reference import SpacetimeReference, heading_quat
from toolkit.errors import JtError
from toolkit.motion import rotations as rot


@pytest.fixture(scope="module")
def run():
    return SpacetimeReference("run")


def test_every_shipped_humanoid_clip_loads_and_samples():
    from toolkit.motion.skeletons import humanoid_clip_paths

    for path in humanoid_clip_paths():
        r = SpacetimeReference(path)
        for phase in (0.0, 0.37, 1.0):
            s = r.at_phase(phase)
            assert s.q.shape == (43,) and s.qd.shape == (34,) and s.ee.shape == (4, 3)
            assert np.all(np.isfinite(s.q)) and np.all(np.isfinite(s.qd))


def test_frames_are_the_clips_own_poses_at_the_clips_own_height(run):
    """No global lift (issue: the run's one frame at -6.8 cm lifted every frame by it)."""
    c = run.clip
    for i in (0, 7, c.n_frames - 2):
        s = run.sample(c.times[i])
        np.testing.assert_allclose(s.q[:3], c.root_pos[i], atol=1e-9)
        assert rot.quat_angle(s.q[3:7], c.root_rot[i]) < 1e-6
    assert run.lowest.min() < -0.06 and np.median(run.lowest) > -0.01  # the clip's own dip is kept


def _yaw(q):
    h = heading_quat(q)
    return 2.0 * np.arctan2(h[1], h[3])


def test_without_the_turn_each_cycle_shifts_the_root_by_the_offset_with_no_vertical_part():
    r = SpacetimeReference("run", cycle_turn=False)
    assert r.turn == 0.0 and r.offset[1] == 0.0 and abs(r.offset[0]) > 1.0
    for phase in (0.1, 0.6):
        a, b = r.at_phase(phase, 0), r.at_phase(phase, 3)
        np.testing.assert_allclose(b.q[:3] - a.q[:3], 3 * r.offset, atol=1e-9)
        np.testing.assert_allclose(b.com - a.com, 3 * r.offset, atol=1e-9)
        np.testing.assert_allclose(b.q[3:], a.q[3:], atol=1e-9)
        np.testing.assert_allclose(b.qd, a.qd, atol=1e-9)
        np.testing.assert_allclose(b.ee, a.ee, atol=1e-9)
        assert a.phase == pytest.approx(phase) and b.phase == pytest.approx(phase)


@pytest.mark.parametrize("clip, turn", [("walk", 0.12), ("run", -0.09)])
def test_each_cycle_is_the_first_moved_by_the_clips_own_turn(clip, turn):
    """Cycle k = the first cycle under the k-th power of the rigid motion taking the first frame's
    root onto the last frame's: the heading advances by ``turn`` per cycle, positions turn about
    the cycle's start, joints, heights and heading-frame end effectors are the first cycle's."""
    r = SpacetimeReference(clip)
    assert r.turn == pytest.approx(turn, abs=0.01)
    c = r.clip
    assert float(np.remainder(_yaw(c.root_rot[-1]) - _yaw(c.root_rot[0]) - r.turn + np.pi, 2 * np.pi) - np.pi) \
        == pytest.approx(0.0, abs=1e-12)
    for k in (-2, 1, 3):
        for phase in (0.1, 0.6):
            a, b = r.at_phase(phase, 0), r.at_phase(phase, k)
            ang = k * r.turn
            R = np.array([[np.cos(ang), 0, np.sin(ang)], [0, 1, 0], [-np.sin(ang), 0, np.cos(ang)]])
            p0 = np.array([c.root_pos[0, 0], 0.0, c.root_pos[0, 2]])
            np.testing.assert_allclose(b.q[:3], R @ (a.q[:3] - p0) + r.cycle_origin(k), atol=1e-9)
            np.testing.assert_allclose(b.com, R @ (a.com - p0) + r.cycle_origin(k), atol=1e-9)
            assert np.remainder(_yaw(b.q[3:7]) - _yaw(a.q[3:7]) - ang + np.pi, 2 * np.pi) - np.pi \
                == pytest.approx(0.0, abs=1e-9)
            np.testing.assert_allclose(b.q[7:], a.q[7:], atol=1e-12)
            np.testing.assert_allclose(b.qd[:3], R @ a.qd[:3], atol=1e-9)
            np.testing.assert_allclose(b.qd[3:6], R @ a.qd[3:6], atol=1e-9)
            np.testing.assert_allclose(b.qd[6:], a.qd[6:], atol=1e-12)
            np.testing.assert_allclose(b.ee, a.ee, atol=1e-12)
    np.testing.assert_allclose(r.cycle_origin(1), p0 + r.offset, atol=1e-12)  # T(p0) = p_N


def test_a_tracking_characters_path_stays_inside_the_com_bounds_for_20_s():
    """Outside reference: a character that tracks the walk's steps exactly, integrated from the
    clip's own heading-frame root steps and turns at 600 Hz (across a seam the step of the turned reference, as the data jumps there), stays
    within the 0.2 m CoM bounds of the reference over 20 s; the authors' shifted-only cycles leave
    them within the 20 s (the heading snaps back at every seam)."""
    r, flat = SpacetimeReference("walk"), SpacetimeReference("walk", cycle_turn=False)
    dt, n = 1.0 / 600.0, 12000
    s0 = r.sample(0.0)
    pos, yaw = np.array([s0.q[0], 0.0, s0.q[2]]), _yaw(s0.q[3:7])
    worst, worst_flat = 0.0, 0.0
    for i in range(n):
        t = i * dt
        a, b = r.sample(t), r.sample(t + dt)  # the clip's local step: heading-frame displacement and turn
        la, lb = flat.sample(t % r.period), flat.sample((t % r.period) + dt)
        d = lb.q[:3] - la.q[:3]
        ya = _yaw(la.q[3:7])
        local = np.array([np.cos(ya) * d[0] - np.sin(ya) * d[2], 0.0, np.sin(ya) * d[0] + np.cos(ya) * d[2]])
        dyaw = np.remainder(_yaw(lb.q[3:7]) - ya + np.pi, 2 * np.pi) - np.pi
        if (t % r.period) + dt > r.period:  # across the seam the clip's data jumps: take the turned reference's step
            d = b.q[:3] - a.q[:3]
            yb = _yaw(a.q[3:7])
            local = np.array([np.cos(yb) * d[0] - np.sin(yb) * d[2], 0.0, np.sin(yb) * d[0] + np.cos(yb) * d[2]])
            dyaw = np.remainder(_yaw(b.q[3:7]) - yb + np.pi, 2 * np.pi) - np.pi
        pos = pos + np.array([np.cos(yaw) * local[0] + np.sin(yaw) * local[2], 0.0,
                              -np.sin(yaw) * local[0] + np.cos(yaw) * local[2]])
        yaw += dyaw
        if i % 20 == 19:
            worst = max(worst, float(np.hypot(*(pos - r.sample(t + dt).q[:3])[[0, 2]])))
            worst_flat = max(worst_flat, float(np.hypot(*(pos - flat.sample(t + dt).q[:3])[[0, 2]])))
    print(f"tracking vs turned reference {worst:.3f} m, vs shifted-only {worst_flat:.3f} m")
    assert worst < 0.05
    assert worst_flat > 0.2


def test_velocities_have_no_spike_at_the_loop_seam(run):
    """Outside reference: finite differences of the sampled root position match the velocities,
    and the velocity is continuous across the seam (as inside a cycle)."""
    T, h = run.period, 1e-4
    seam = [run.sample(T + e).qd for e in (-h, h)]
    assert np.abs(seam[1] - seam[0]).max() < 1e-2 * max(1.0, np.abs(seam[0]).max())
    ts = np.linspace(0.0, 2 * T, 97)
    qd = np.array([run.sample(t).qd for t in ts])
    jumps = np.abs(np.diff(qd, axis=0)).max(axis=1)
    assert jumps.max() < 5.0 * np.median(jumps) + 1.0
    dt = 1.0 / 600.0
    for t in (0.3, T - dt / 2, T):
        fd = (run.sample(t + dt).q[:3] - run.sample(t - dt).q[:3]) / (2 * dt)
        np.testing.assert_allclose(run.sample(t).qd[:3], fd, atol=0.3)


def test_a_non_looping_clip_holds_its_last_frame():
    r = SpacetimeReference("jump", loop=False)
    T = r.period
    last = r.sample(T)
    for t in (T + 0.1, T + 5.0):
        s = r.sample(t)
        np.testing.assert_allclose(s.q, last.q, atol=1e-12)
        np.testing.assert_array_equal(s.qd, 0.0)
        assert s.phase == 1.0
    np.testing.assert_array_equal(r.offset, r.offset * 0)


def test_heading_axis_z_follows_the_roots_z_axis():
    yaw = rot.quat_from_axis_angle(np.array([0.0, 1.0, 0.0]), 0.8)
    pitch = rot.quat_from_axis_angle(np.array([0.0, 0.0, 1.0]), 1.4)  # x tilts towards up
    q = rot.quat_multiply(yaw, pitch)
    assert rot.quat_angle(heading_quat(q, "z"), yaw) < 1e-9
    assert rot.quat_angle(heading_quat(q, "x"), yaw) < 1e-9  # still defined away from vertical
    flip = rot.quat_multiply(yaw, rot.quat_from_axis_angle(np.array([0.0, 0.0, 1.0]), np.pi / 2))
    assert rot.quat_angle(heading_quat(flip, "z"), yaw) < 1e-9  # x points straight up: z still works


@pytest.mark.parametrize("clip, match", [("no_such_clip", "no such clip"), (__file__, "not a DeepMimic")])
def test_bad_clips_are_one_line_errors(clip, match, tmp_path):
    with pytest.raises(JtError, match=match) as e:
        SpacetimeReference(clip)
    assert "\n" not in str(e.value)
    with pytest.raises(JtError, match="heading_axis"):
        SpacetimeReference("run", heading_axis="y")


def test_heading_quat_is_the_general_yaw_quaternion_bit_for_bit():
    """``heading_quat`` builds the yaw rotation without ``quat_from_axis_angle``'s general case:
    the same quaternion, signed zeros included, for both heading axes."""
    import math

    from jt_tasks.spacetime.reference import HEADING_AXES, heading_quat
    from toolkit.motion import rotations as rot

    rng = np.random.default_rng(4)
    for _ in range(500):
        q = rot.quat_normalize(rng.standard_normal(4))
        for axis in ("x", "z"):
            a = HEADING_AXES[axis]
            f = rot.quat_rotate(q[None], a)[0]
            yaw = math.atan2(-f[2], f[0]) - math.atan2(-a[2], a[0])
            expect = rot.quat_from_axis_angle(np.array([0.0, 1.0, 0.0]), yaw)
            got = heading_quat(q, axis)
            assert np.array_equal(got, expect) and np.array_equal(np.signbit(got), np.signbit(expect))


def test_the_shipped_walks_turn_is_a_yaw_jump_at_its_mirrored_half():
    """The data ``straighten`` answers: the walk's root yaw jumps back 0.125 rad between frames 18
    and 19 (its second step is the first mirrored, yaw negated, not offset) while its root path
    goes straight along x; the 0.12 rad per cycle is that jump."""
    c = SpacetimeReference("walk", cycle_turn=False).clip
    yaw = np.array([_yaw(c.root_rot[i]) for i in range(c.n_frames)])
    step = np.diff(yaw)
    assert step[18] == pytest.approx(0.125, abs=0.005)
    assert np.abs(np.delete(step, 18)).max() < 0.03
    np.testing.assert_allclose(yaw[19:19 + 18], -yaw[:18], atol=1e-3)
    assert abs(c.root_pos[:, 2]).max() < 0.02 and c.root_pos[-1, 0] > 1.2


@pytest.mark.parametrize("clip", ["walk", "run"])
def test_a_straightened_clip_faces_as_its_first_frame_and_keeps_the_rest(clip):
    from toolkit.motion.rotations import quat_rotate

    raw, r = SpacetimeReference(clip), SpacetimeReference(clip, straighten=True)
    a, b = raw.clip, r.clip
    assert abs(raw.turn) > 0.05 and r.turn == pytest.approx(0.0, abs=1e-9)
    up = np.array([0.0, 1.0, 0.0])
    for i in range(b.n_frames):
        assert _yaw(b.root_rot[i]) == pytest.approx(_yaw(a.root_rot[0]), abs=1e-6)
        # pitch and roll kept: the root's up axis makes the same angle with the vertical
        assert quat_rotate(b.root_rot[i], up)[1] == pytest.approx(quat_rotate(a.root_rot[i], up)[1], abs=1e-9)
    np.testing.assert_array_equal(b.root_pos, a.root_pos)
    np.testing.assert_array_equal(b.joints, a.joints)
    # no cycle turns: cycle 3 faces as cycle 0, shifted by three offsets
    s0, s3 = r.at_phase(0.4, 0), r.at_phase(0.4, 3)
    assert rot.quat_angle(s0.q[3:7], s3.q[3:7]) < 1e-6
    np.testing.assert_allclose(s3.q[:3] - s0.q[:3], 3 * r.offset, atol=1e-9)


def test_straighten_leaves_a_clip_that_does_not_loop():
    raw, r = SpacetimeReference("walk", loop=False), SpacetimeReference("walk", loop=False, straighten=True)
    np.testing.assert_array_equal(r.clip.root_rot, raw.clip.root_rot)
