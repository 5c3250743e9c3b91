"""The take-off state's jumping intention (``v_y``, ``000`` §8) and where its default comes from."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from conftest import make_spec


def test_default_v_y_is_the_jump_clips_liftoff_speed():
    from omegaconf import OmegaConf

    from jt_tasks.jumping.takeoff import liftoff_vertical_speed
    from toolkit.config import conf_dir

    measured = liftoff_vertical_speed("jump")
    assert 1.8 < measured < 2.3  # a standing jump's lift-off, not a run's bounce
    assert liftoff_vertical_speed("run") < 1.0  # the steady run carries no jumping intention
    for task in ("highjump", "obstacle", "longjump"):
        yaml = OmegaConf.load(Path(conf_dir()) / "task" / f"{task}.yaml")
        assert yaml.v_y == pytest.approx(measured, abs=0.01), task


def test_v_y_replaces_only_the_vertical_root_speed():
    from jt_tasks.jumping.takeoff import facing_velocities, takeoff_state

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


@pytest.mark.parametrize("v_y, cleared", [(None, False), (2.06, True)])
def test_holding_the_takeoff_pose_clears_a_low_bar_only_with_the_jumping_intention(v_y, cleared):
    """Without the vertical speed the body runs into the 0.5 m wall whatever the pose; with it,
    simply holding the take-off pose carries the CoM over the bar plane (what makes the
    curriculum's first level learnable)."""
    from jt_tasks.jumping.env import JumpEnv

    env = JumpEnv(make_spec(v_y=v_y), seed=0)
    try:
        env.reset(seed=0)
        hold = env.skeleton.joints_to_dofs(env._q0[7:]).astype(np.float32)
        done, info = False, {}
        while not done:
            _, _, done, _, info = env.step(hold)
        assert bool(info["crossed"]) is cleared
        if not cleared:
            assert info["reason"] == "touched the bar"
    finally:
        env.close()
