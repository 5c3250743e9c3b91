"""Rollout workers: bootstrapping at time limits, seeding, in-process vs executor actors."""

import gymnasium
import numpy as np
import pytest
import torch

from toolkit.rl.networks import ActorCritic
from toolkit.rl.rollout import RolloutWorker, merge_batches, start_workers
from toolkit.rl.sanity import GymEnvFn


class Drift(gymnasium.Env):
    """1-D point: obs (x, t), x += clip(a); terminates at |x| > 3, truncated after 4 steps."""

    observation_space = gymnasium.spaces.Box(-np.inf, np.inf, (2,), np.float32)
    action_space = gymnasium.spaces.Box(-1.0, 1.0, (1,), np.float32)

    def reset(self, seed=None, options=None):
        super().reset(seed=seed)
        self.x, self.t = float(self.np_random.uniform(-0.5, 0.5)), 0
        return np.array([self.x, self.t], np.float32), {}

    def step(self, a):
        self.x += float(a[0])
        self.t += 1
        obs = np.array([self.x, self.t], np.float32)
        return obs, -self.x**2, abs(self.x) > 3, self.t >= 4, {"x": self.x}


def drift_fn(seed):
    return Drift()


def _weights(obs_dim, act_dim, seed=0):
    torch.manual_seed(seed)
    m = ActorCritic(obs_dim, act_dim, (16,), (16,), -np.ones(act_dim), np.ones(act_dim))
    m.norm.mean.fill_(0.1)
    return m.numpy_state()


def test_truncation_bootstraps_from_final_observation():
    w = RolloutWorker(drift_fn, 7, [0, 1], (16,), (16,))
    w.set_weights(_weights(2, 1))
    b = w.collect(10, 0.9, 0)
    assert b["truncated"].any() and not (b["truncated"] & b["terminated"]).any()
    for t, j in zip(*np.nonzero(b["truncated"])):
        final = np.array([b["obs"][t, j, 0] + np.clip(b["actions"][t, j, 0], -1, 1), 4.0],
                         np.float32)
        with torch.no_grad():
            v = float(w.model.value(torch.from_numpy(final[None]))[0])
        assert b["next_values"][t, j] == pytest.approx(v, abs=1e-5)
        if t + 1 < 10:
            assert b["obs"][t + 1, j, 1] == 0  # a fresh episode follows
    # not done: the next value is the next row's value
    live = ~(b["truncated"] | b["terminated"])[:-1]
    np.testing.assert_array_equal(b["next_values"][:-1][live], b["values"][1:][live])
    assert b["episodes"] and all(e["length"] <= 4 and "x" in e for e in b["episodes"])
    # stored log-probs are those of the unbounded samples under N(mu(s), 0.9^2)
    with torch.no_grad():
        mu = w.model.mean_action(torch.from_numpy(b["obs"]))
    ref = torch.distributions.Normal(mu, 0.9).log_prob(torch.from_numpy(b["actions"])).sum(-1)
    np.testing.assert_allclose(b["logp"], ref.numpy(), atol=1e-5)
    assert (np.abs(b["actions"]) > 1).any()  # samples are stored unclipped


def test_collect_is_seeded_by_offset():
    w1 = RolloutWorker(drift_fn, 3, [0], (16,), (16,))
    w2 = RolloutWorker(drift_fn, 3, [0], (16,), (16,))
    for w in (w1, w2):
        w.set_weights(_weights(2, 1))
    a, b, c = w1.collect(6, 0.3, 5), w2.collect(6, 0.3, 5), w2.collect(6, 0.3, 6)
    for k in ("obs", "actions", "rewards", "logp"):
        np.testing.assert_array_equal(a[k], b[k])
    assert not np.array_equal(a["actions"], c["actions"])


def test_executor_actors_give_the_same_batch_as_in_process():
    from jt_executors.local import LocalExecutor

    env_fn = GymEnvFn("Pendulum-v1", max_episode_steps=7)
    weights = _weights(3, 1)
    batches = []
    for ex in (None, LocalExecutor(LocalExecutor.Config(workers=2))):
        ws = start_workers(env_fn, 11, 2, 2, (16,), (16,), True, True, ex)
        try:
            assert ws.size == 2
            ws.call("set_weights", [(weights,)] * 2)
            batches.append(merge_batches(ws.call("collect", [(20, 0.4, 3)] * 2)))
        finally:
            ws.close()
            if ex is not None:
                ex.close()
    local, remote = batches
    assert local["obs"].shape == (20, 4, 3) and local["truncated"].any()
    for k in ("obs", "actions", "logp", "values", "next_values", "rewards", "terminated",
              "truncated"):
        np.testing.assert_array_equal(local[k], remote[k], err_msg=k)
    assert local["episodes"] == remote["episodes"]
