"""action=raw: the action is the PD target."""

import numpy as np

from action_contract import ActionSpaceContract
from jt_actions.raw import RawActionSpace
from toolkit.motion import HUMANOID
from toolkit.priors.limits import joint_limits


class TestRaw(ActionSpaceContract):
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
