"""Networks: log-density, shapes, action bounds, observation statistics, env checker."""

import gymnasium
import numpy as np
import pytest
import torch

from toolkit.rl.gym_check import check_gym_env
from toolkit.rl.networks import ActorCritic, RunningObsStats, gaussian_log_prob


def test_log_prob_matches_torch_distributions():
    g = torch.Generator().manual_seed(0)
    mean = torch.randn(32, 5, generator=g)
    act = mean + 0.3 * torch.randn(32, 5, generator=g) + 0.1
    for std in (0.5, 0.1, 1.7):
        ref = torch.distributions.Normal(mean, std).log_prob(act).sum(-1)
        torch.testing.assert_close(gaussian_log_prob(mean, std, act), ref)


def test_paper_sized_networks():
    m = ActorCritic(197, 41, (1024, 512), (1024, 512), -np.ones(41), np.ones(41))
    lin = [l for l in m.pi if isinstance(l, torch.nn.Linear)]
    assert [(l.in_features, l.out_features) for l in lin] == [(197, 1024), (1024, 512), (512, 41)]
    assert all(isinstance(l, torch.nn.ReLU) for l in m.pi if not isinstance(l, torch.nn.Linear))
    mu, v = m(torch.zeros(3, 197))
    assert mu.shape == (3, 41) and v.shape == (3,)
    assert not any(n.startswith("norm") for n, _ in m.named_parameters())  # normaliser frozen


def test_actions_clipped_or_scaled_to_box():
    low, high = np.array([-2.0, 0.0]), np.array([2.0, 1.0])
    raw = ActorCritic(3, 2, (8,), (8,), low, high, normalize_actions=False)
    np.testing.assert_allclose(raw.to_env(np.array([[3.0, 0.5], [-1.0, -4.0]])),
                               [[2.0, 0.5], [-1.0, 0.0]])
    scaled = ActorCritic(3, 2, (8,), (8,), low, high, normalize_actions=True)
    np.testing.assert_allclose(scaled.to_env(np.array([[0.5, 0.0], [-3.0, 1.0]])),
                               [[1.0, 0.5], [-2.0, 1.0]])


def test_running_obs_stats_and_freeze():
    rng = np.random.default_rng(0)
    x = rng.normal(3.0, 2.0, size=(1000, 4))
    s = RunningObsStats(4, max_count=1000, eps=0.01)
    s.update(x[:400])
    s.update(x[400:])
    mean, std = s.mean_std()
    np.testing.assert_allclose(mean, x.mean(0))
    np.testing.assert_allclose(std, x.std(0) + 0.01)
    s.update(x + 100.0)  # frozen after max_count samples
    np.testing.assert_allclose(s.mean_std()[0], x.mean(0))


def test_gym_check_accepts_pendulum_and_rejects_broken_env():
    assert isinstance(check_gym_env(gymnasium.make("Pendulum-v1").unwrapped), list)

    class Broken(gymnasium.Env):
        observation_space = gymnasium.spaces.Box(-1, 1, (2,), np.float32)
        action_space = gymnasium.spaces.Box(-1, 1, (1,), np.float32)

        def reset(self, seed=None, options=None):
            super().reset(seed=seed)
            return np.zeros(3, np.float32), {}  # wrong shape

        def step(self, a):
            return np.zeros(2, np.float32), 0.0, False, False, {}

    with pytest.raises(AssertionError):
        check_gym_env(Broken())
