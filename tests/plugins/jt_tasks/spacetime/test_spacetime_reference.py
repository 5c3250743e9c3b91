"""The reference motion: any clip, any phase, per-cycle root offset, seam-free velocities, hold."""

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


def test_frames_are_the_clips_own_poses_lifted(run):
    c = run.clip
    for i in (0, 7, c.n_frames - 2):
        s = run.sample(c.times[i])
        np.testing.assert_allclose(s.q[:3], c.root_pos[i] + [0, run.lift, 0], atol=1e-9)
        assert rot.quat_angle(s.q[3:7], c.root_rot[i]) < 1e-6


def test_each_cycle_shifts_the_root_by_the_offset_with_no_vertical_part(run):
    assert run.offset[1] == 0.0 and abs(run.offset[0]) > 1.0
    for phase in (0.1, 0.6):
        a, b = run.at_phase(phase, 0), run.at_phase(phase, 3)
        np.testing.assert_allclose(b.q[:3] - a.q[:3], 3 * run.offset, atol=1e-9)
        np.testing.assert_allclose(b.com - a.com, 3 * run.offset, atol=1e-9)
        np.testing.assert_allclose(b.q[3:], a.q[3:], atol=1e-9)
        np.testing.assert_allclose(b.qd, a.qd, atol=1e-9)
        np.testing.assert_allclose(b.ee, a.ee, atol=1e-9)
        assert a.phase == pytest.approx(phase) and b.phase == pytest.approx(phase)


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
