"""Episodes across iterations (``reset_each_iteration=False``) and the episode-start hook data."""

import gymnasium
import numpy as np
import pytest
import torch

from toolkit.rl.networks import ActorCritic
from toolkit.rl.ppo import PPOConfig, train
from toolkit.rl.rollout import RolloutWorker
from toolkit.rl.sanity import GymEnvFn
from toolkit.rl.ppo import TIMING as ppo_timing

PENDULUM = GymEnvFn("Pendulum-v1", max_episode_steps=50)
TIMING = set(ppo_timing)  # wall-clock keys: they differ between identical runs
LENGTH = 5  # PhaseEnv episode length


class PhaseEnv(gymnasium.Env):
    """Obs (phase, t); the phase is drawn at reset from ``phases`` (an attribute a trainer hook can
    set) and returned in the reset info; reward = phase each step; terminates after 5 steps."""

    observation_space = gymnasium.spaces.Box(-np.inf, np.inf, (2,), np.float32)
    action_space = gymnasium.spaces.Box(-1.0, 1.0, (1,), np.float32)

    def __init__(self):
        self.phases = [0.5, 1.0, 2.0, 3.0]

    def reset(self, seed=None, options=None):
        super().reset(seed=seed)
        self.phase, self.t = float(self.np_random.choice(self.phases)), 0
        info = {"phase": self.phase, "value": -999.0, "_private": 1.0, "label": "not a number"}
        return np.array([self.phase, 0.0], np.float32), info

    def step(self, a):
        self.t += 1
        return np.array([self.phase, self.t], np.float32), self.phase, self.t >= LENGTH, False, {}


def phase_env(seed):
    return PhaseEnv()


def cfg(**kw) -> PPOConfig:
    base = dict(policy_hidden=(16,), value_hidden=(16,), samples_per_iteration=48, minibatch_size=24,
                epochs=1, policy_lr=1e-3, value_lr=1e-2, gamma=1.0, lam=1.0, obs_norm=False,
                total_samples=3 * 48, n_workers=2, envs_per_worker=2, checkpoint_every=100, seed=2)
    base.update(kw)
    return PPOConfig(**base)


def gravity(it, samples, stats):
    return {"g": 10.0 - 0.5 * it}


def _assert_same_history(a, b):
    assert set(a) == set(b)
    for k in set(a) - TIMING:  # NaN (no episode finished) equals NaN
        np.testing.assert_array_equal(np.asarray(a[k]), np.asarray(b[k]), err_msg=k)


@pytest.mark.parametrize("optimizer", ["sgd", "adam"])
def test_run_on_episodes_resume_bit_identically(tmp_path, optimizer):
    # 4 envs x 30 steps per iteration, 50-step episodes, restarts every 2 iterations (60 steps):
    # an episode ends in every second iteration, so episodes span iterations
    c = dict(samples_per_iteration=120, total_samples=6 * 120, reset_each_iteration=False,
             checkpoint_every=2, policy_hidden=(32,), value_hidden=(32,), minibatch_size=60, epochs=2,
             policy_lr=1e-3, value_lr=1e-3, optimizer=optimizer, n_workers=2, envs_per_worker=2, seed=3)
    whole = train(PENDULUM, PPOConfig(**c), checkpoint_path=tmp_path / "whole.h5", on_iteration=gravity)
    assert whole.history["n_episodes"] == [0.0, 4.0] * 3
    assert whole.history["mean_length"][1::2] == [50.0] * 3
    path = tmp_path / "split.h5"
    first = train(PENDULUM, PPOConfig(**{**c, "total_samples": 4 * 120}), checkpoint_path=path,
                  on_iteration=gravity)
    assert first.iterations == 4
    resumed = train(PENDULUM, PPOConfig(**c), checkpoint_path=path, on_iteration=gravity)
    assert resumed.iterations == 6
    _assert_same_history(resumed.history, whole.history)
    for k, v in whole.model.state_dict().items():
        assert torch.equal(v, resumed.model.state_dict()[k]), k
    # restarts at the checkpoint boundaries matter: without them the episodes run on and differ
    never = train(PENDULUM, PPOConfig(**{**c, "checkpoint_every": 100}))
    assert never.history["n_episodes"] == [0.0, 4.0, 0.0, 4.0, 4.0, 0.0]


def _start_steps(n_iterations, steps, restart_every):
    """Expected batch rows of the episode starts of 5-step episodes: ``[[rows] per iteration]``."""
    out, t0 = [], 0  # t0: global step at which the current run of episodes began
    for i in range(n_iterations):
        if i % restart_every == 0:
            t0 = i * steps
        out.append([t - i * steps for t in range(i * steps, (i + 1) * steps) if (t - t0) % LENGTH == 0])
    return out


@pytest.mark.parametrize("reset_each_iteration, checkpoint_every", [(True, 100), (False, 100), (False, 2)])
def test_starts_carry_reset_info_value_and_lambda_return(reset_each_iteration, checkpoint_every):
    seen = []

    def hook(it, samples, stats):
        seen.append(stats.starts)
        assert all(isinstance(v, float) for v in stats.values())
        return {"phases": [7.0]} if it == 2 else None  # the reset distribution of every worker

    c = cfg(reset_each_iteration=reset_each_iteration, checkpoint_every=checkpoint_every, total_samples=4 * 48)
    train(phase_env, c, on_iteration=hook)
    # 12 steps per env per iteration: starts every 5 steps, carried over iteration boundaries
    expected = _start_steps(4, 12, 1 if reset_each_iteration else checkpoint_every)
    for it, starts in enumerate(seen):
        assert [s["step"] for s in starts] == [t for t in expected[it] for _ in range(4)], it
        assert [s["env"] for s in starts] == [0, 1, 2, 3] * len(expected[it])
        for s in starts:
            assert set(s) == {"phase", "value", "env", "step", "target"}
            assert s["value"] != -999.0  # V(s0), not the info's entry
            if s["step"] + LENGTH <= 12:  # finished in the batch: γ = λ = 1 target = the return
                assert s["target"] == pytest.approx(LENGTH * s["phase"], rel=1e-6)
    # the hook's attribute reached every env of both workers from the next reset on
    assert all(s["phase"] == 7.0 for s in seen[2] if s["step"] > 0) and seen[2]
    assert all(s["phase"] == 7.0 for s in seen[3]) and seen[3]
    assert any(s["phase"] != 7.0 for s in seen[1])
    # V(s0) of iteration 1 is the initial network's value (obs_norm off: identity normaliser)
    torch.manual_seed(c.seed)
    model = ActorCritic(2, 1, c.policy_hidden, c.value_hidden, -np.ones(1), np.ones(1))
    with torch.no_grad():
        for s in seen[0]:
            v = float(model.value(torch.tensor([[s["phase"], 0.0]])))
            assert s["value"] == pytest.approx(v, abs=1e-6)


def test_worker_reports_starts_at_their_first_observation():
    w = RolloutWorker(phase_env, 0, [4, 5], (8,), (8,), reset_each_collect=False)
    torch.manual_seed(0)
    w.set_weights(ActorCritic(2, 1, (8,), (8,), -np.ones(1), np.ones(1)).numpy_state())
    a = w.collect(5, 0.1, 0)  # episodes end at the last step: their successors start next call
    assert [(s["step"], s["env"]) for s in a["starts"]] == [(0, 4), (0, 5)]
    b = w.collect(3, 0.1, 1, reset=False)
    assert [(s["step"], s["env"]) for s in b["starts"]] == [(0, 4), (0, 5)]
    assert np.all(b["obs"][0, :, 1] == 0)  # t = 0: these are first observations
    for s in b["starts"]:
        assert b["obs"][0, s["env"] - 4, 0] == s["phase"]
    c = w.collect(2, 0.1, 2, reset=False)  # t = 3, 4: nothing starts (the next one is pending)
    assert c["starts"] == [] and np.all(c["obs"][0, :, 1] == 3) and c["terminated"][-1].all()
    d = w.collect(3, 0.1, 3, reset=True)  # a seeded restart replaces the pending starts
    assert [(s["step"], s["env"]) for s in d["starts"]] == [(0, 4), (0, 5)]
    assert np.all(d["obs"][0, :, 1] == 0)
    e = w.collect(6, 0.1, 4)  # reset=None: as reset_each_collect (False here), so run on
    assert [(s["step"], s["env"]) for s in e["starts"]] == [(2, 4), (2, 5)]
