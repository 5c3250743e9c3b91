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


def test_an_output_scale_multiplies_the_mean_not_the_noise_and_survives_a_checkpoint(tmp_path):
    """``out_scale`` (an env's ``policy_output_scale``): the policy mean is the MLP's output times
    the scale; log-densities use the scaled mean with sigma in the env's units; save/load keeps it."""
    from toolkit.rl import checkpoint as ckpt
    from toolkit.rl.config import PPOConfig

    torch.manual_seed(0)
    scale = np.array([1.0, 2.0, 4.0])
    a = ActorCritic(5, 3, (8,), (8,), -np.ones(3) * 9, np.ones(3) * 9, out_scale=scale)
    torch.manual_seed(0)
    b = ActorCritic(5, 3, (8,), (8,), -np.ones(3) * 9, np.ones(3) * 9)
    obs = torch.randn(4, 5)
    np.testing.assert_allclose(a.mean_action(obs).detach().numpy(), b.mean_action(obs).detach().numpy() * scale,
                               rtol=1e-6)
    mu, _ = a(obs)
    np.testing.assert_allclose(mu.detach().numpy(), a.mean_action(obs).detach().numpy())
    path = ckpt.save_training(tmp_path / "ppo.h5", PPOConfig(policy_hidden=(8,), value_hidden=(8,)), a, torch.optim.SGD(a.pi.parameters(), 0.1),
                              torch.optim.SGD(a.v.parameters(), 0.1), RunningObsStats(5, 10),
                              np.random.default_rng(0), 1, 10, {}, {}, {}, a.low, a.high)
    back = ckpt.load_policy(path)
    np.testing.assert_array_equal(back.out_scale, scale)
    np.testing.assert_allclose(back.mean_action(obs).detach().numpy(), a.mean_action(obs).detach().numpy(), rtol=1e-6)
