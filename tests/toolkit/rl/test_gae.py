"""GAE(λ) / TD(λ) against hand-computed values, and the σ schedule."""

import numpy as np
import pytest

from toolkit.rl.ppo import PPOConfig, action_std, compute_gae


def test_gae_hand_computed_with_truncation_and_termination():
    # env 0: truncated (time limit) after step 1, bootstrapped from the final obs value 10.
    # env 1: terminated at step 2 (its next value 99 must be ignored).
    rewards = np.array([[1, 1], [2, 1], [3, 1], [4, 1]], float)
    values = np.array([[0.5, 2], [1.0, 2], [1.5, 2], [2.0, 2]])
    next_values = np.array([[1.0, 2], [10.0, 2], [2.0, 99], [3.0, 2]])
    term = np.array([[0, 0], [0, 0], [0, 1], [0, 0]], bool)
    trunc = np.array([[0, 0], [1, 0], [0, 0], [0, 0]], bool)
    adv, tgt = compute_gae(rewards, values, next_values, term, trunc, gamma=0.9, lam=0.5)
    # by hand, γλ = 0.45:
    # env 0: δ = [1.4, 10, 3.3, 4.7]; A3 = 4.7, A2 = 3.3 + .45·4.7, A1 = 10 (episode end), A0 = 1.4 + .45·10
    # env 1: δ = [0.8, 0.8, -1, 0.8]; A3 = .8, A2 = -1, A1 = .8 - .45, A0 = .8 + .45·.35
    np.testing.assert_allclose(adv[:, 0], [5.9, 10.0, 5.415, 4.7])
    np.testing.assert_allclose(adv[:, 1], [0.9575, 0.35, -1.0, 0.8])
    np.testing.assert_allclose(tgt, adv + values)
    np.testing.assert_allclose(tgt[:, 0], [6.4, 11.0, 6.915, 6.7])


def test_targets_are_recursive_lambda_returns():
    # TD(λ) return: G_t = r_t + γ((1-λ) V(s_{t+1}) + λ G_{t+1}), G_T bootstrapped with V(s_T).
    rng = np.random.default_rng(0)
    T, gamma, lam = 7, 0.97, 0.8
    r, v = rng.normal(size=(T, 1)), rng.normal(size=(T + 1, 1))
    zeros = np.zeros((T, 1), bool)
    _, tgt = compute_gae(r, v[:-1], v[1:], zeros, zeros, gamma, lam)
    g = v[T, 0]
    expected = np.zeros(T)
    for t in reversed(range(T)):
        boot = v[t + 1, 0]
        g = r[t, 0] + gamma * ((1 - lam) * boot + lam * (g if t < T - 1 else boot))
        expected[t] = g
    np.testing.assert_allclose(tgt[:, 0], expected)


def test_lambda_one_gamma_one_is_monte_carlo():
    r = np.array([[1.0], [2.0], [3.0]])
    v = np.array([[0.3], [0.2], [0.1]])
    term = np.array([[0], [0], [1]], bool)
    nxt = np.array([[0.2], [0.1], [123.0]])  # V(s_{t+1}); ignored after the termination
    adv, tgt = compute_gae(r, v, nxt, term, np.zeros_like(term), 1.0, 1.0)
    np.testing.assert_allclose(tgt[:, 0], [6.0, 5.0, 3.0])
    np.testing.assert_allclose(adv[:, 0], [5.7, 4.8, 2.9])


@pytest.mark.parametrize(
    "samples, std", [(0, 0.5), (2.5e6, 0.4), (5e6, 0.3), (1e7, 0.1), (3e7, 0.1)]
)
def test_std_annealing_schedule(samples, std):
    # 000 §4.1: σ linear 0.5 -> 0.1 over the first 1e7 samples, then constant.
    assert action_std(samples, PPOConfig()) == pytest.approx(std)


def test_paper_defaults():
    c = PPOConfig()
    assert c.policy_hidden == (1024, 512) and c.value_hidden == (1024, 512)
    assert (c.samples_per_iteration, c.epochs, c.minibatch_size) == (4096, 5, 256)
    assert (c.clip, c.policy_lr, c.value_lr, c.gamma, c.lam) == (0.02, 2.5e-5, 1e-2, 1.0, 0.95)
    assert (c.std_start, c.std_end, c.std_anneal_samples) == (0.5, 0.1, 1e7)
