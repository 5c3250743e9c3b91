"""jt's RL tasks through ``gymnasium.make`` (the path other RL libraries take)."""

from __future__ import annotations

import numpy as np
import pytest

RL_TASKS = ("highjump", "obstacle", "longjump", "runup", "spacetime", "getup")


def test_every_rl_task_is_registered_and_only_those():
    import gymnasium

    import toolkit.gym_envs as ge

    ids = ge.register_all()
    assert sorted(ids) == sorted(f"jt/{t}-v0" for t in RL_TASKS)
    assert all(i in gymnasium.registry for i in ids)
    assert "jt/standing_jump-v0" not in gymnasium.registry  # an optimisation task, no policy


@pytest.mark.parametrize("task", RL_TASKS)
def test_gymnasium_make_passes_the_env_checker(task):
    import gymnasium

    from toolkit.rl.gym_check import check_gym_env

    env = gymnasium.make(f"toolkit.gym_envs:jt/{task}-v0", overrides=["action=raw"], seed=0)
    try:
        check_gym_env(env.unwrapped)
        obs, _ = env.reset(seed=1)
        assert env.observation_space.contains(obs)
        obs, r, term, trunc, info = env.step(env.action_space.sample())
        assert np.isfinite(r) and isinstance(term, bool)
    finally:
        env.close()


def test_overrides_and_point_reach_the_environment():
    import gymnasium

    from jt_tasks.takeoff.state import facing_velocities

    vy = {}
    for override in ("task.v_y=2.06", "task.v_y=null"):
        env = gymnasium.make("toolkit.gym_envs:jt/highjump-v0", overrides=["action=raw", override],
                             point={"omega_x": -1.0})
        env.reset(seed=0)
        v, w = facing_velocities(*env.unwrapped.sim.state())
        assert w[0] == pytest.approx(-1.0, abs=1e-6)
        vy[override] = v[1]
        env.close()
    assert vy["task.v_y=2.06"] == pytest.approx(2.06, abs=1e-6) and abs(vy["task.v_y=null"]) < 0.3


def test_a_task_without_an_environment_says_so_in_one_line():
    from toolkit.errors import JtError
    from toolkit.gym_envs import make

    with pytest.raises(JtError, match="has no Gymnasium environment"):
        make("standing_jump")
