"""Slow: PPO learns Pendulum-v1 (the sanity benchmark recorded in docs/ppo.md)."""

import pytest

from toolkit.rl.sanity import run_sanity


@pytest.mark.slow
def test_ppo_learns_pendulum():
    r = run_sanity("Pendulum-v1", total_samples=200_000, seed=0)
    first = r["curve"][0][1]
    assert first < -900  # a random policy
    assert r["final_return"] > -400  # mean over the last 5 iterations (40 episodes)
    assert r["samples"] == 200_000
