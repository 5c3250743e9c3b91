"""Step-wise std and learning-rate schedules (getup §5.6); empty schedules change nothing."""

import numpy as np
import pytest
import torch

from toolkit.rl import checkpoint as ckpt
from toolkit.rl.ppo import PPOConfig, action_std, learning_rates, train
from toolkit.rl.sanity import GymEnvFn
from toolkit.rl.ppo import TIMING as ppo_timing

ENV = GymEnvFn("Pendulum-v1", max_episode_steps=50)
TIMING = set(ppo_timing)  # wall-clock keys: they differ between identical runs
DEFAULT_KEYS = ["mean_return", "mean_length", "n_episodes", "mean_reward", "policy_loss", "value_loss",
                "clip_frac", "approx_kl", "epochs_run", "explained_variance", "action_std",
                "samples_per_s", "collect_s", "update_s", "hook_s"]


def tiny(**kw) -> PPOConfig:
    base = dict(policy_hidden=(32,), value_hidden=(32,), samples_per_iteration=256, minibatch_size=128,
                epochs=2, policy_lr=1e-3, value_lr=1e-3, std_anneal_samples=2048, total_samples=4 * 256,
                n_workers=2, envs_per_worker=2, checkpoint_every=1, seed=7)
    base.update(kw)
    return PPOConfig(**base)


def _learning(history):
    return {k: v for k, v in history.items() if k not in TIMING}


def _same_model(a, b):
    return all(torch.equal(v, b.state_dict()[k]) for k, v in a.state_dict().items())


def test_schedule_functions():
    c = PPOConfig(std_schedule=[[0, 0.6], [2e7, 0.5], [4e7, 0.3]],
                  lr_schedule=[[0, 1e-4, 1e-3], [2e7, 2e-5, 5e-4]])
    assert [action_std(s, c) for s in (0, 2e7 - 1, 2e7, 3e7, 4e7, 1e9)] == [0.6, 0.6, 0.5, 0.5, 0.3, 0.3]
    assert learning_rates(0, c) == (1e-4, 1e-3) and learning_rates(2e7, c) == (2e-5, 5e-4)
    plain = PPOConfig()
    assert action_std(5e6, plain) == pytest.approx(0.3)  # the linear anneal, unchanged
    assert learning_rates(5e6, plain) == (plain.policy_lr, plain.value_lr)


def test_empty_schedules_keep_the_history_keys():
    assert list(train(ENV, tiny(total_samples=256)).history) == DEFAULT_KEYS


def test_std_schedule_is_followed():
    res = train(ENV, tiny(std_schedule=[[0, 0.6], [512, 0.3]]))
    assert res.history["action_std"] == [0.6, 0.6, 0.3, 0.3]


def test_lr_schedule_reaches_the_optimisers(tmp_path):
    plain = train(ENV, tiny())
    assert np.all(np.isfinite(plain.history["mean_return"]))
    same = train(ENV, tiny(lr_schedule=[[0, 1e-3, 1e-3]]))  # the config's own rates: no change
    assert _learning(same.history) == {**_learning(plain.history), "policy_lr": [1e-3] * 4, "value_lr": [1e-3] * 4}
    assert _same_model(same.model, plain.model)
    path = tmp_path / "ppo.h5"
    step = train(ENV, tiny(lr_schedule=[[0, 1e-3, 1e-3], [512, 1e-2, 1e-4]]), checkpoint_path=path)
    assert step.history["policy_lr"] == [1e-3, 1e-3, 1e-2, 1e-2] and step.history["value_lr"][2:] == [1e-4] * 2
    groups, _ = ckpt.load(path)
    assert [g["lr"] for g in groups["policy_optim"]["param_groups"]] == [1e-2]
    assert [g["lr"] for g in groups["value_optim"]["param_groups"]] == [1e-4]
    # the first two iterations are the plain run's; then the new rates change the updates
    assert step.history["policy_loss"][:2] == plain.history["policy_loss"][:2]
    assert step.history["value_loss"][2:] != plain.history["value_loss"][2:]
    assert not _same_model(step.model, plain.model)


@pytest.mark.parametrize("optimizer", ["sgd", "adam"])
def test_scheduled_runs_resume_bit_identically(tmp_path, optimizer):
    c = dict(optimizer=optimizer, std_schedule=[[0, 0.6], [256, 0.4], [768, 0.2]],
             lr_schedule=[[0, 1e-3, 1e-3], [512, 3e-4, 2e-3]])
    whole = train(ENV, tiny(**c))
    path = tmp_path / "split.h5"
    train(ENV, tiny(total_samples=2 * 256, **c), checkpoint_path=path)
    assert ckpt.load(path)[0]["policy_optim"]["param_groups"][0]["lr"] == 1e-3  # saved before the step
    resumed = train(ENV, tiny(**c), checkpoint_path=path)
    assert resumed.iterations == 4
    assert _learning(resumed.history) == _learning(whole.history)
    assert whole.history["action_std"] == [0.6, 0.4, 0.4, 0.2]
    assert _same_model(resumed.model, whole.model)
    assert np.all(np.isfinite(whole.history["mean_return"]))
