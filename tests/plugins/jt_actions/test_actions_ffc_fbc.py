"""action=ffc_fbc: the reference pose at the phase plus a correction (002 §4.2, Fig. 4)."""

import numpy as np
import pytest

from filter_contract import FilterOption
from toolkit.testing.action import ActionSpaceContract
from jt_actions.ffc_fbc import FFCFBCActionSpace, unwrap_expmaps
from toolkit.errors import JtError
from toolkit.motion import HUMANOID
from toolkit.motion import rotations as rot


def _angles(space, dofs_a, dofs_b):
    """Per-joint rotation differences (rad) between two dof rows."""
    qa, qb = HUMANOID.dofs_to_joints(dofs_a), HUMANOID.dofs_to_joints(dofs_b)
    out = []
    for j, s in zip(HUMANOID.joints, HUMANOID.q_slices.values()):
        out.append(rot.quat_angle(qa[s], qb[s]) if j.kind == "spherical" else abs(qa[s.start] - qb[s.start]))
    return np.array(out)


class TestFFCFBC(ActionSpaceContract, FilterOption):
    def make(self):
        return FFCFBCActionSpace({"name": "ffc_fbc", "clip": "walk"})

    def obs(self, step):
        return {"phase": 0.13 * step}

    @pytest.mark.parametrize("clip, tol", [("walk", 0.01), ("backflip", 0.05)])
    def test_zero_correction_reproduces_the_clip(self, clip, tol):
        space = FFCFBCActionSpace({"clip": clip, "clip_to_limits": False})
        c = space.clip
        for k in (0, 1, c.n_frames // 2, c.n_frames - 1):  # at frames: the clip's pose exactly
            phi = c.times[k] / c.duration
            got = space.targets(np.zeros(28), {"phase": phi})
            assert _angles(space, got, HUMANOID.joints_to_dofs(c.joints[k])).max() < 1e-9
        for phi in np.linspace(0.01, 0.99, 23):  # between frames: linear in exp maps (~ slerp)
            _, _, joints = c.sample_phase(phi)
            got = space.targets(np.zeros(28), phi)
            assert _angles(space, got, HUMANOID.joints_to_dofs(joints)).max() < tol
            k = np.searchsorted(c.times, phi * c.duration) - 1
            w = (phi * c.duration - c.times[k]) / (c.times[k + 1] - c.times[k])
            a, b = HUMANOID.joints_to_dofs(c.joints[k]), HUMANOID.joints_to_dofs(c.joints[k + 1])
            if np.abs(b - a).max() < 1.0:  # no exp-map seam between these frames
                np.testing.assert_allclose(got, (1 - w) * a + w * b, atol=1e-9)

    def test_correction_adds_and_phase_sources(self):
        space = self.make()
        ref = space.reference(0.25)
        dq = np.zeros(28)
        dq[3] = 0.1  # neck exp map x
        np.testing.assert_allclose(space.targets(dq, {"phase": 0.25}), ref + dq, atol=1e-12)
        class Obs:
            phase = 0.25
        np.testing.assert_allclose(space.targets(np.zeros(28), Obs()), ref, atol=1e-12)
        space.set_phase(1.25)  # a looping clip wraps
        assert space.phase == pytest.approx(0.25)
        space.reset()
        assert space.phase == 0.0
        space.reset(0.5)
        assert space.phase == 0.5
        assert space.penalty() == 1.0

    def test_unwrap_and_unknown_clip(self):
        axis = np.array([0.0, 0.0, 1.0])
        angles = np.linspace(2.8, 3.5, 8)  # crosses pi: the log map flips the axis there
        raw = rot.quat_to_expmap(rot.quat_from_expmap(angles[:, None] * axis))
        assert np.abs(np.diff(raw[:, 2])).max() > 5.0
        np.testing.assert_allclose(unwrap_expmaps(raw)[:, 2], angles, atol=1e-9)
        with pytest.raises(JtError) as e:
            FFCFBCActionSpace({"clip": "moonwalk"})
        assert "walk" in str(e.value)
        with pytest.raises(JtError):
            FFCFBCActionSpace({"clip": "laikago_walk"})  # a clip of another character


#: LimHigh - LimLow per DoF of the authors' humanoid3d character file, as its JSON lists them
#: (chest, neck, right hip, knee, ankle, shoulder, elbow, then the left side)
AUTHORS_A_STD = [2.4] * 3 + [2.0] * 3 + [2.4, 2.0, 4.14] + [3.14] + [2.0, 2.0, 3.14] + [3.64, 3.0, 3.84] + [3.14] \
    + [2.4, 2.0, 4.14] + [3.14] + [2.0, 2.0, 3.14] + [3.64, 3.0, 3.84] + [3.14]


def test_the_output_scale_is_the_authors_joint_range_per_dof():
    """002 authors' code: the actor's mean offset is a_std * net(s), a_std = LimHigh - LimLow
    (2-4.14 rad); the correction itself is unscaled (the scale lives in the policy network)."""
    space = FFCFBCActionSpace({"clip": "walk"})
    np.testing.assert_allclose(space.output_scale(), AUTHORS_A_STD, atol=1e-12)
    dq = np.full(28, 0.1)
    np.testing.assert_allclose(space.targets(dq, 0.25), space.finish(space.reference(0.25) + dq), atol=1e-12)
    assert FFCFBCActionSpace({"clip": "walk", "output_scale": "none"}).output_scale() is None


def test_a_bad_output_scale_is_one_line():
    with pytest.raises(JtError, match="output_scale") as e:
        FFCFBCActionSpace({"clip": "walk", "output_scale": "joint"})
    assert "\n" not in str(e.value)


def test_use_clip_switches_the_reference_and_keeps_each_track():
    """A task whose episodes follow different clips (task=getup) swaps the reference; switching
    back gives the first clip's targets again, bit for bit."""
    from toolkit.motion import load_clip
    from jt_actions.ffc_fbc import resolve_clip

    space = FFCFBCActionSpace({"clip": "walk", "clip_to_limits": False})
    walk = space.reference(0.3).copy()
    getup = load_clip(resolve_clip("getup_facedown"))
    space.use_clip(getup, name="getup_facedown")
    assert space.clip is getup
    first = space.reference(0.0)
    np.testing.assert_allclose(first, HUMANOID.joints_to_dofs(getup.joints[0]), atol=1e-9)
    assert np.abs(space.reference(0.3) - walk).max() > 0.1
    plain = space.reference(0.5).copy()
    space.use_clip(getup.mirror())  # the mirrored clip: left and right swapped
    assert np.abs(space.reference(0.5) - plain).max() > 0.1
    space.use_clip(space._tracks[next(iter(space._tracks))][0])  # the walk, kept from __init__
    np.testing.assert_array_equal(space.reference(0.3), walk)


def test_use_clip_of_another_skeleton_is_one_line():
    from toolkit.motion import load_clip
    from jt_actions.ffc_fbc import resolve_clip

    space = FFCFBCActionSpace({"clip": "walk"})
    with pytest.raises(JtError, match="laikago"):
        space.use_clip(load_clip(resolve_clip("laikago_walk")), name="laikago_walk")
