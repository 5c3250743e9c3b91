"""task=getup with action=ffc_fbc: the episode's clip pose at the curve's clock under the policy
(issue 52's lever 1, ours): the target at a curve time, the held last frame, the velocities, the
mirrored clips and the composition check."""

import numpy as np
import pytest

from toolkit.errors import JtError
from toolkit.motion import HUMANOID

FFC = ["action=ffc_fbc", "action.clip=getup_facedown", "action.clip_to_limits=false",
       "task.curves=[facedown,faceup,facedown_mirror,faceup_mirror]"]


def _env(*overrides):
    from getup_helpers import make_task

    return make_task(*FFC, *overrides).make_env(seed=0)


def _clip_dofs_at(clip, phase):
    """The clip's joint dofs ``(28,)`` at ``phase``, interpolated in unwrapped exp maps as the FFC does."""
    from jt_actions.ffc_fbc import FFCFBCActionSpace

    space = FFCFBCActionSpace({"clip": "walk", "clip_to_limits": False})
    space.use_clip(clip)
    return space.reference(phase)


@pytest.mark.parametrize("curve, mirrored", [("facedown", False), ("faceup_mirror", True)])
def test_zero_correction_targets_the_clip_pose_at_the_curve_clock(curve, mirrored):
    from jt_tasks.getup.curves import load_getup_clip

    env = _env("task.ffc_lead=2")
    try:
        env.reset(options={"kind": "clip", "curve": curve})
        clip = load_getup_clip(env.curve.clip, mirrored)
        assert env.curve.mirrored is mirrored
        for _ in range(5):
            q = env.pd_targets(np.zeros(env.action_space.shape))
            want = _clip_dofs_at(clip, env.clip_phase(env.t + 2 / 30.0))
            np.testing.assert_allclose(HUMANOID.joints_to_dofs(q[7:]), want, atol=1e-9)
            env.step(np.zeros(env.action_space.shape))
        assert 0.0 < env.clip_phase(env.t) < 0.2
    finally:
        env.close()


def test_the_last_frame_is_held_through_the_standing_phase():
    env = _env()
    try:
        env.reset(options={"kind": "standing", "curve": "facedown"})
        assert env.clip_phase(env.t) == 1.0  # a standing start begins at T
        assert env.clip_phase(env.curve.duration + 2.5) == 1.0
        assert env.clip_phase(0.5 * env.curve.duration) == pytest.approx(0.5)
    finally:
        env.close()


def test_target_velocities_are_the_clips_scaled_to_the_curve_and_zero_once_it_ends():
    from jt_tasks.getup.curves import load_getup_clip
    from jt_tasks.takeoff.state import reference_state

    env = _env("task.ffc_velocity=true", "task.time_scale=2.0")
    try:
        env.reset(options={"kind": "clip", "curve": "facedown", "at": 1.0})
        clip = load_getup_clip("getup_facedown", False)
        qd = env.pd_velocity_targets()
        length = float(clip.times[-1] - clip.times[0])
        assert env.curve.duration == pytest.approx(2.0 * length, rel=1e-6)  # time_scale stretches the curve
        jv = reference_state(clip, env.clip_phase(env.t) * length)[5] * 0.5
        np.testing.assert_allclose(qd[6:], jv, atol=1e-9)
        assert np.all(qd[:6] == 0.0) and np.abs(jv).max() > 0.1
        env.reset(options={"kind": "standing", "curve": "facedown"})
        assert not np.any(env.pd_velocity_targets())
    finally:
        env.close()
    env = _env()  # ffc_velocity off: zero target velocities, as 002 §4.2
    try:
        env.reset(options={"kind": "clip", "curve": "facedown"})
        assert env.pd_velocity_targets() is None
    finally:
        env.close()


def test_an_authored_curve_under_a_feed_forward_is_one_line():
    from toolkit.config import compose, validate

    with pytest.raises(JtError, match="situp_roll has no clip"):
        validate(compose(["task=getup", "action=ffc_fbc", "task.curves=[facedown,situp_roll]",
                          "task.eval_regions=[flat]", "task.terrain=null", "~curriculum"]))
