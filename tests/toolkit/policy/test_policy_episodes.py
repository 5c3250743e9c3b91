"""One deterministic episode, its typed record and the self-closing env (toolkit.policy.episodes),
on the minimal policy task's real environment (stand_example.py)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))


class Zero:
    """The mean action of an untrained policy: zero (raw actions: the rest pose's PD targets)."""

    def __init__(self, n: int) -> None:
        self.n = n

    def act(self, obs: np.ndarray) -> np.ndarray:
        return np.zeros(self.n)


@pytest.fixture()
def task():
    from omegaconf import OmegaConf
    from stand_example import StandTask

    from toolkit.config import compose

    cfg = compose(["task=runup", "experiment=smoke"])  # smoke-sized PPO, raw actions
    OmegaConf.set_struct(cfg, False)
    cfg.task = {"name": "stand", "time_limit": 0.2}
    return StandTask(cfg)


def by_hand(env, model, options=None):
    """The loop every task used to write: (return, steps, last info)."""
    obs, _ = env.reset(seed=0, options=options)
    ret, steps, done, info = 0.0, 0, False, {}
    while not done:
        obs, r, te, tr, info = env.step(model.act(obs).astype(np.float32))
        ret, steps, done = ret + r, steps + 1, te or tr
    return ret, steps, info


def test_rollout_is_the_loop_every_task_wrote_and_records_each_state(task):
    from toolkit.policy.episodes import Rollout, opened_env, rollout

    with opened_env(task.make_env, seed=0) as env:
        model = Zero(env.action_space.shape[0])
        ro = rollout(env, model, task.record)
        ret, steps, info = by_hand(env, model)
        again = rollout(env, model, task.record)
        hz = env.control_hz
    assert isinstance(ro, Rollout)
    assert ro.return_ == pytest.approx(ret, abs=0) and ro.steps == steps and ro.info == info
    assert steps >= 1 and steps <= round(0.2 * hz)  # fell or reached the 0.2 s time limit
    assert ro.time.shape == (steps + 1,) and ro.root.shape == (steps + 1, 7) and ro.com.shape == (steps + 1, 3)
    assert ro.time[0] == pytest.approx(0.0, abs=1e-9) and np.all(np.diff(ro.time) > 0)
    assert ro.frames == [] and ro.notes == {}
    np.testing.assert_array_equal(again.com, ro.com)  # deterministic: the same episode twice


def test_frames_follow_every_recorded_state_and_nothing_is_recorded_without_record(task):
    from toolkit.policy.episodes import opened_env, rollout

    with opened_env(task.make_env, seed=0) as env:
        model = Zero(env.action_space.shape[0])
        bare = rollout(env, model)
        shot = rollout(env, model, frames=2, width=32, height=24)
    assert bare.series == {} and bare.frames == []
    with pytest.raises(KeyError):
        bare.time
    assert shot.steps == bare.steps and len(shot.frames) == shot.steps + 1
    assert np.asarray(shot.frames[0]).shape[:2] == (24, 32)


def test_a_stop_request_stops_before_the_episode_starts():
    from toolkit.execution import stopping
    from toolkit.policy.episodes import rollout

    class Env:
        resets = 0

        def reset(self, **kw):
            Env.resets += 1
            raise AssertionError("reset after a stop request")

    stopping.request("SIGTERM")
    try:
        with pytest.raises(KeyboardInterrupt, match="SIGTERM"):
            rollout(Env(), Zero(1))
    finally:
        stopping.clear()
    assert Env.resets == 0


def test_opened_env_closes_the_env_however_the_block_ends():
    from toolkit.policy.episodes import opened_env

    closed = []

    class Env:
        def __init__(self, name, seed=None):
            self.name, self.seed = name, seed

        def close(self):
            closed.append(self.name)

    with opened_env(Env, "a", seed=3) as env:
        assert (env.name, env.seed) == ("a", 3) and closed == []
    assert closed == ["a"]
    with pytest.raises(ValueError, match="inside"):
        with opened_env(Env, "b"):
            raise ValueError("inside")
    assert closed == ["a", "b"]


def test_opened_env_closes_a_real_env(task):
    from toolkit.policy.episodes import opened_env

    with opened_env(task.make_env, seed=0) as env:
        assert env.sim is not None and env.reset(seed=0)[0].shape == env.observation_space.shape
    assert env.sim is None  # CharacterEnv.close let its simulator go
