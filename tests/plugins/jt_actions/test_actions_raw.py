"""action=raw: the action is the PD target."""

import numpy as np

from filter_contract import FilterOption
from toolkit.testing.action import ActionSpaceContract
from jt_actions.raw import RawActionSpace
from toolkit.motion import HUMANOID
from toolkit.priors.limits import joint_limits


class TestRaw(ActionSpaceContract, FilterOption):
    def make(self):
        return RawActionSpace({"name": "raw"}, HUMANOID)

    def test_targets_are_the_action(self):
        space = self.make()
        assert space.dim == 28
        low, high = space.bounds()
        np.testing.assert_array_equal(low, joint_limits(HUMANOID)[0])
        a = np.full(28, -0.4)
        a[[HUMANOID.dof_slices["right_elbow"].start, HUMANOID.dof_slices["left_elbow"].start]] = 1.0
        np.testing.assert_array_equal(space.targets(a), a)
        a[HUMANOID.dof_slices["right_knee"].start] = 0.3  # hyper-extended knee: clipped to the URDF's 0
        assert space.targets(a)[HUMANOID.dof_slices["right_knee"].start] == 0.0
        unclipped = RawActionSpace({"clip_to_limits": False})
        assert unclipped.targets(a)[HUMANOID.dof_slices["right_knee"].start] == 0.3
        assert space.penalty() == 1.0


class TestRawAroundStart(ActionSpaceContract, FilterOption):
    """``around_start``: the action is an offset from the episode's initial pose."""

    def make(self):
        space = RawActionSpace({"name": "raw", "around_start": True}, HUMANOID)
        space.anchor(np.concatenate([np.zeros(7), HUMANOID.dofs_to_joints(np.full(28, 0.1))]))
        return space

    def test_zero_action_holds_the_start_pose(self):
        space = RawActionSpace({"name": "raw", "around_start": True}, HUMANOID)
        lo, hi = joint_limits(HUMANOID)
        start = 0.5 * (lo + hi)  # a pose within every limit
        start[HUMANOID.dof_slices["right_knee"].start] = -0.5  # a bent knee
        space.anchor(np.concatenate([np.zeros(7), HUMANOID.dofs_to_joints(start)]))
        np.testing.assert_allclose(space.targets(np.zeros(28)), start, atol=1e-12)
        a = np.zeros(28)
        a[HUMANOID.dof_slices["right_knee"].start] = 0.2
        assert space.targets(a)[HUMANOID.dof_slices["right_knee"].start] == np.float64(-0.3)
        low, high = space.bounds()
        np.testing.assert_allclose(high, -low)  # offsets span a joint range either way
        assert (high > 0).all()
