"""bar_height driving the real PPO trainer: attributes reach the envs, state is checkpointed, a
resumed run ends in the same curriculum state as an uninterrupted one."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

from jt_curricula.bar_height import BarHeightCurriculum

EPISODE = 8


class BarEnv(gymnasium.Env):
    """8-step episodes whose only reward, at the end, is the current bar height."""

    observation_space = gymnasium.spaces.Box(-1.0, 1.0, (2,), np.float32)
    action_space = gymnasium.spaces.Box(-1.0, 1.0, (1,), np.float32)

    def __init__(self) -> None:
        self.bar_height, self.control_hz, self.c_offset, self.t = 0.5, 10.0, 48.0, 0

    def reset(self, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        return np.zeros(2, np.float32), {}

    def step(self, action):
        self.t += 1
        done = self.t >= EPISODE
        info = {"bar_height": self.bar_height, "control_hz": self.control_hz, "c_offset": self.c_offset}
        return np.full(2, self.t / EPISODE, np.float32), self.bar_height if done else 0.0, done, False, info


def bar_env(seed):
    return BarEnv()


def tiny(**kw):
    from toolkit.rl.ppo import PPOConfig

    base = dict(policy_hidden=(8,), value_hidden=(8,), samples_per_iteration=64, minibatch_size=32,
                epochs=1, total_samples=6 * 64, n_workers=1, envs_per_worker=2, checkpoint_every=1, seed=3)
    base.update(kw)
    return PPOConfig(**base)


CFG = {"z_min": 0.5, "z_max": 1.25, "dz": 0.25, "reward_threshold": 0.9}


pytestmark = pytest.mark.usefixtures("one_torch_thread")


def test_curriculum_drives_the_envs_through_the_trainer(tmp_path):
    from toolkit.rl import checkpoint as ckpt
    from toolkit.rl.ppo import train

    cur = BarHeightCurriculum(CFG)
    extra = cur.bind({})
    seen = []

    def hook(it, samples, stats):
        seen.append(sorted({e["bar_height"] for e in stats.episodes}))
        return cur.on_iteration(it, samples, stats)

    res = train(bar_env, tiny(), checkpoint_path=tmp_path / "c.h5", on_iteration=hook, extra=extra)
    # mean return = bar height; accumulator: 0.5, 1.0 > 0.9 → z 0.75 | 0.75, 1.5 → 1.0 |
    # 1.0 > 0.9 → 1.25 = z_max | 1.25 > 0.9 → reset, capped
    assert seen == [[0.5], [0.5], [0.75], [0.75], [1.0], [1.25]]
    assert res.history["mean_return"] == pytest.approx([0.5, 0.5, 0.75, 0.75, 1.0, 1.25])
    assert cur.z == 1.25 and cur.at_max() and cur.frozen() and cur.accumulator == 0.0
    groups = ckpt.load(tmp_path / "c.h5")[0]
    assert groups["extra"]["curriculum"] == cur.state()
    assert groups["env_attrs"] == {"bar_height": 1.25, "control_hz": 30.0, "c_offset": 15.0}


def test_resumed_run_ends_in_the_same_state(tmp_path):
    from toolkit.rl.ppo import train

    whole = BarHeightCurriculum(CFG)
    train(bar_env, tiny(), on_iteration=whole.on_iteration, extra=whole.bind({}))
    path = tmp_path / "split.h5"
    first = BarHeightCurriculum(CFG)
    train(bar_env, tiny(total_samples=3 * 64), checkpoint_path=path, on_iteration=first.on_iteration,
          extra=first.bind({}))
    assert first.z == 0.75 and first.accumulator == 0.75
    second = BarHeightCurriculum(CFG)  # a new process: fresh object, state comes from the checkpoint
    extra = second.bind({})
    train(bar_env, tiny(), checkpoint_path=path, on_iteration=second.on_iteration, extra=extra)
    assert second.state() == whole.state() and extra["curriculum"] == whole.state()
