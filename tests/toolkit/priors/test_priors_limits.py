"""Joint limits of the dof layout: URDF ranges for revolute joints, canonical exp maps otherwise."""

import numpy as np

from toolkit.motion import HUMANOID
from toolkit.motion import rotations as rot
from toolkit.priors.limits import canonical_expmaps, joint_limits, limit_targets, within_limits


def test_limits_come_from_the_urdf():
    low, high = joint_limits(HUMANOID)
    sl = HUMANOID.dof_slices
    assert low.shape == high.shape == (28,)
    for side in ("right", "left"):  # humanoid.urdf: knees [-3.14, 0], elbows [0, 3.14]
        assert (low[sl[f"{side}_knee"]][0], high[sl[f"{side}_knee"]][0]) == (-3.14, 0.0)
        assert (low[sl[f"{side}_elbow"]][0], high[sl[f"{side}_elbow"]][0]) == (0.0, 3.14)
    assert np.allclose(low[sl["chest"]], -np.pi) and np.allclose(high[sl["right_hip"]], np.pi)


def test_urdf_limits_are_what_pybullet_reads():
    """The limits read from the URDF file equal PyBullet's ``getJointInfo`` (the reference) on
    every skeleton, joint by joint (unlimited: lower >= upper there, +-pi here)."""
    import pybullet as pb

    from toolkit.motion.skeletons import SKELETONS, data_dir

    for sk in SKELETONS.values():
        low, high = joint_limits(sk)
        c = pb.connect(pb.DIRECT)
        try:
            pb.setAdditionalSearchPath(data_dir(), physicsClientId=c)
            body = pb.loadURDF(sk.urdf, globalScaling=sk.scale, flags=pb.URDF_MAINTAIN_LINK_ORDER,
                               physicsClientId=c)
            for j, s in zip(sk.joints, sk.dof_slices.values()):
                if j.kind == "spherical":
                    continue
                lo, hi = pb.getJointInfo(body, j.bullet_index, physicsClientId=c)[8:10]
                want = (lo, hi) if lo < hi else (-np.pi, np.pi)
                assert (low[s][0], high[s][0]) == want, (sk.name, j.name)
        finally:
            pb.disconnect(c)


def test_limit_targets_keeps_rotations_and_clips_angles():
    rng = np.random.default_rng(0)
    dofs = rng.uniform(-5.0, 5.0, (50, 28))
    out = limit_targets(HUMANOID, dofs)
    assert within_limits(HUMANOID, out)
    assert not within_limits(HUMANOID, dofs)
    for j, s in zip(HUMANOID.joints, HUMANOID.dof_slices.values()):
        if j.kind == "spherical":  # same rotation, |v| <= pi
            assert np.all(np.linalg.norm(out[:, s], axis=1) <= np.pi + 1e-9)
            ang = rot.quat_angle(rot.quat_from_expmap(out[:, s]), rot.quat_from_expmap(dofs[:, s]))
            assert np.all(ang < 1e-9)
    knee = HUMANOID.dof_slices["right_knee"].start
    assert np.all(out[:, knee] <= 0.0) and np.all(out[:, knee] >= -3.14)
    small = np.full(28, -0.3)
    small[[HUMANOID.dof_slices["right_elbow"].start, HUMANOID.dof_slices["left_elbow"].start]] = 0.3
    np.testing.assert_array_equal(canonical_expmaps(HUMANOID, small), small)
    np.testing.assert_array_equal(limit_targets(HUMANOID, small), small)
