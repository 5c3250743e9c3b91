"""Slim checkpoints (``toolkit.rl.checkpoint.slim``): what a shipped skill holds acts exactly as the
full checkpoint it was cut from, and is refused where training state is needed."""

import h5py
import numpy as np
import pytest
import torch

from toolkit.errors import JtError
from toolkit.rl import checkpoint as ckpt
from toolkit.rl.ppo import PPOConfig, train
from toolkit.rl.sanity import GymEnvFn

ENV = GymEnvFn("Pendulum-v1", max_episode_steps=50)


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    """A trained PPO checkpoint (two iterations on Pendulum, with an env attribute set)."""
    path = tmp_path_factory.mktemp("full") / "ppo.h5"
    cfg = PPOConfig(policy_hidden=(24, 16), value_hidden=(20,), samples_per_iteration=128, minibatch_size=64,
                    epochs=2, total_samples=256, n_workers=1, envs_per_worker=2, checkpoint_every=1, seed=3)
    train(ENV, cfg, checkpoint_path=path, on_iteration=lambda it, samples, stats: {"g": 9.0 + it})
    return path


def test_slim_acts_as_the_full_checkpoint(full, tmp_path):
    dst = ckpt.slim(full, tmp_path / "policy.h5")
    with h5py.File(dst, "r") as f:
        assert sorted(f.keys()) == sorted(ckpt.SLIM_GROUPS)
        assert sorted(f["obs_norm"].keys()) == ["mean", "std"]
    groups, attrs = ckpt.load(dst)
    full_groups, full_attrs = ckpt.load(full)
    assert attrs["slim"] and attrs["samples"] == full_groups["counters"]["samples"] == 256
    assert attrs["iteration"] == full_groups["counters"]["iteration"]
    assert groups["env_attrs"] == full_groups["env_attrs"] == {"g": 11.0}  # after iteration 2
    assert (attrs["obs_dim"], attrs["act_dim"], attrs["config"]) == \
        (full_attrs["obs_dim"], full_attrs["act_dim"], full_attrs["config"])
    assert dst.stat().st_size < full.stat().st_size / 2

    a, b = ckpt.load_policy(full), ckpt.load_policy(dst)
    obs = np.random.default_rng(0).normal(size=(64, a.obs_dim)).astype(np.float32) * 3.0
    for o in obs:
        np.testing.assert_array_equal(a.act(o), b.act(o))
    with torch.no_grad():
        assert torch.equal(a.norm.mean, b.norm.mean) and torch.equal(a.norm.std, b.norm.std)


def test_slim_of_a_slim_file_and_of_no_checkpoint(full, tmp_path):
    once = ckpt.slim(full, tmp_path / "a.h5")
    twice = ckpt.slim(once, tmp_path / "b.h5")
    assert ckpt.load_attrs(twice)["samples"] == 256  # kept from the attributes
    ckpt.save(tmp_path / "empty.h5", {"env_attrs": {}}, {"obs_dim": 3, "act_dim": 1})
    with pytest.raises(ValueError, match="no policy, obs_norm group"):
        ckpt.slim(tmp_path / "empty.h5", tmp_path / "c.h5")


def test_task_evaluate_refuses_a_slim_policy(full, tmp_path):
    from toolkit.policy.trained import trained_policy

    dst = ckpt.slim(full, tmp_path / "policy.h5")
    with pytest.raises(JtError, match="is a slim policy .* replay it with: jt play"):
        trained_policy({"task": {"evaluate": str(dst)}}, "stand")
    assert trained_policy({"task": {"evaluate": str(full)}}, "stand") == full.resolve()
