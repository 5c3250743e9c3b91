"""Training loop: same seed → same curve; checkpoints round-trip; a split run equals a whole one."""

import dataclasses

import h5py
import numpy as np
import pytest
import torch

from toolkit.rl import checkpoint as ckpt
from toolkit.rl.ppo import TIMING as ppo_timing
from toolkit.rl.ppo import PPOConfig, train
from toolkit.rl.sanity import GymEnvFn

ENV = GymEnvFn("Pendulum-v1", max_episode_steps=50)
TIMING = set(ppo_timing)  # wall-clock keys: they differ between identical runs


def tiny(**kw) -> PPOConfig:
    # paper defaults (SGD + momentum, clip, γ, λ...) with small nets and batches; a big value lr
    # so that parameters visibly change in a few iterations
    base = dict(policy_hidden=(32, 32), value_hidden=(32, 32), samples_per_iteration=256,
                minibatch_size=64, epochs=2, policy_lr=1e-3, value_lr=1e-3,
                std_anneal_samples=2048, total_samples=4 * 256, n_workers=2, envs_per_worker=2,
                checkpoint_every=1, seed=5)
    base.update(kw)
    return PPOConfig(**base)


def curriculum(it, samples, stats):
    """A stand-in curriculum: changes Pendulum's gravity every iteration."""
    return {"g": 10.0 - 0.5 * it}


def _learning_stats(history):
    return {k: v for k, v in history.items() if k not in TIMING}


def _params(model):
    return {k: v.clone() for k, v in model.state_dict().items()}


def _assert_same_model(a, b):
    for k, v in a.items():
        assert torch.equal(v, b[k]), k


def test_same_seed_same_training_curve():
    r1 = train(ENV, tiny())
    r2 = train(ENV, tiny())
    h1, h2 = _learning_stats(r1.history), _learning_stats(r2.history)
    assert len(h1["policy_loss"]) == 4 and h1 == h2
    assert np.all(np.isfinite(h1["mean_return"])) and np.all(np.isfinite(h1["value_loss"]))
    _assert_same_model(_params(r1.model), _params(r2.model))
    r3 = train(ENV, tiny(seed=6))
    assert _learning_stats(r3.history)["mean_return"] != h1["mean_return"]
    assert r1.samples == 4 * 256 and r1.iterations == 4
    assert h1["action_std"] == pytest.approx([0.5, 0.45, 0.4, 0.35])


def test_checkpoint_tree_round_trip(tmp_path):
    tree = {"a": {0: torch.arange(3.0), 1: {"m": np.eye(2)}}, "lst": [1, 2.5, "s", None, True],
            "tup": (0.9, 0.999), "empty": {}, "big": 2**70 // 2**10}
    ckpt.save(tmp_path / "x.h5", {"t": tree}, {"config": {"k": [1, 2]}, "n": 3})
    groups, attrs = ckpt.load(tmp_path / "x.h5")
    t = groups["t"]
    assert torch.equal(t["a"][0], torch.arange(3.0)) and np.array_equal(t["a"][1]["m"], np.eye(2))
    assert t["lst"] == [1, 2.5, "s", None, True] and t["tup"] == (0.9, 0.999)
    assert t["empty"] == {} and t["big"] == 2**60 and list(t["a"]) == [0, 1]
    assert attrs["config"] == {"k": [1, 2]} and attrs["n"] == 3
    with pytest.raises(TypeError):
        ckpt.save(tmp_path / "y.h5", {"t": {"bad": object()}}, {})
    assert not (tmp_path / "y.h5").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.h5"], "temp file left behind"


def test_checkpoint_contents_and_load_policy(tmp_path):
    path = tmp_path / "ppo.h5"
    extra = {"bar_height": 1.25}
    res = train(ENV, tiny(total_samples=2 * 256), checkpoint_path=path, extra=extra,
                on_iteration=curriculum)
    assert res.checkpoint_path == path
    with h5py.File(path, "r") as f:
        for g in ("policy", "value", "obs_norm", "policy_optim", "value_optim", "counters", "rng",
                  "env_attrs", "extra", "history"):
            assert g in f, g
        assert "momentum_buffer" in f["policy_optim/state/#int:0"]  # SGD momentum state saved
    groups, attrs = ckpt.load(path)
    assert groups["counters"] == {"iteration": 2, "samples": 512}
    assert groups["extra"] == {"bar_height": 1.25} and groups["env_attrs"] == {"g": 9.0}
    assert groups["obs_norm"]["count"] == 512 and attrs["config"]["seed"] == 5
    model = ckpt.load_policy(path)
    obs = torch.randn(4, 3)
    with torch.no_grad():
        torch.testing.assert_close(model.mean_action(obs), res.model.mean_action(obs))
        torch.testing.assert_close(model.value(obs), res.model.value(obs))
    assert model.act(np.zeros(3, np.float32)).shape == (1,)


@pytest.mark.parametrize("optimizer", ["sgd", "adam"])
def test_split_run_resumes_to_identical_parameters(tmp_path, optimizer):
    whole = train(ENV, tiny(optimizer=optimizer), on_iteration=curriculum)
    path = tmp_path / "split.h5"
    extra = {"note": "first half"}
    first = train(ENV, tiny(optimizer=optimizer, total_samples=2 * 256), checkpoint_path=path,
                  on_iteration=curriculum, extra=extra)
    assert first.iterations == 2
    extra_after = {"note": "overwritten by the checkpoint"}
    second = train(ENV, tiny(optimizer=optimizer), checkpoint_path=path,
                   on_iteration=curriculum, extra=extra_after)
    assert second.iterations == 4 and second.samples == whole.samples
    assert extra_after == {"note": "first half"}
    assert _learning_stats(second.history) == _learning_stats(whole.history)
    _assert_same_model(_params(second.model), _params(whole.model))
    # resume=False starts over (and differs from the resumed run's end state)
    fresh = train(ENV, tiny(optimizer=optimizer, total_samples=256), checkpoint_path=path,
                  resume=False)
    assert fresh.iterations == 1 and ckpt.load(path)[0]["counters"]["iteration"] == 1


def test_curriculum_attrs_reach_the_envs():
    seen = []

    def hook(it, samples, stats):
        assert all(isinstance(v, float) for v in stats.values())  # loggable as-is
        assert len(stats.episodes) == stats["n_episodes"] == 4  # 4 envs x 64 steps, 50-step limit
        assert stats["mean_return"] == pytest.approx(np.mean([e["return"] for e in stats.episodes]))
        seen.append(stats["mean_return"])
        return {"g": 0.0}  # no gravity from iteration 2 on: a different curve

    h_plain = train(ENV, tiny(total_samples=2 * 256)).history["mean_return"]
    train(ENV, tiny(total_samples=2 * 256), on_iteration=hook)
    assert seen[0] == h_plain[0] and seen[1] != h_plain[1]


def test_episodes_span_iterations_without_reset():
    # 4 envs x 30 steps per iteration, 50-step episodes: only complete when they span iterations
    # (without reset_each_iteration, episodes restart only at run start and checkpoint iterations)
    cfg = dict(samples_per_iteration=120, total_samples=3 * 120, checkpoint_every=3)
    cut = train(ENV, tiny(**cfg)).history["n_episodes"]
    span = train(ENV, tiny(reset_each_iteration=False, **cfg)).history["n_episodes"]
    assert cut == [0.0, 0.0, 0.0]
    assert span == [0.0, 4.0, 0.0]


def test_training_with_executor_actors_matches_in_process():
    from jt_executors.local import LocalExecutor

    cfg = tiny(total_samples=2 * 256)
    local = train(ENV, cfg, on_iteration=curriculum)
    with LocalExecutor(LocalExecutor.Config(workers=2)) as ex:
        remote = train(ENV, cfg, executor=ex, on_iteration=curriculum)
    assert _learning_stats(remote.history) == _learning_stats(local.history)
    _assert_same_model(_params(remote.model), _params(local.model))


def test_target_kl_stops_an_update_early():
    """``target_kl`` (CleanRL): an epoch whose mean approximate KL exceeds it ends the update, so a
    tiny threshold leaves one epoch per iteration; None runs them all."""
    full = train(ENV, tiny(epochs=4, n_workers=1, policy_lr=1e-2, optimizer="adam"))
    early = train(ENV, tiny(epochs=4, n_workers=1, policy_lr=1e-2, optimizer="adam", target_kl=1e-9))
    assert full.history["epochs_run"] == [4.0] * 4
    assert early.history["epochs_run"] == [1.0] * 4
    assert early.history["mean_return"][0] == full.history["mean_return"][0]  # same first batch
    loose = train(ENV, tiny(epochs=4, n_workers=1, policy_lr=1e-2, optimizer="adam", target_kl=1e9))
    assert _learning_stats(loose.history) == _learning_stats(full.history)  # never reached: the paper's loop


class ScaledEnvFn:
    """Pendulum whose env declares ``policy_output_scale`` (as ``action=ffc_fbc`` does)."""

    def __call__(self, seed: int):
        env = ENV(seed)
        env.unwrapped.policy_output_scale = np.array([3.0])
        return env


def test_an_env_output_scale_is_the_learners_mean_too():
    """The workers sample around the scaled mean; the learner's log-densities must use the same
    mean, so the first minibatch's ratio is 1: with a tiny actor rate the update's KL and clip
    fraction stay near 0 (a learner that forgot the scale sees KL ~ 1 and clips everything)."""
    cfg = tiny(policy_lr=1e-7, epochs=1, total_samples=256, n_workers=1)
    r = train(ScaledEnvFn(), cfg)
    assert r.model.out_scale is not None and r.model.out_scale[0] == 3.0
    assert r.history["approx_kl"][0] < 1e-3 and r.history["clip_frac"][0] < 0.01


def test_the_update_on_one_thread_is_seeded_and_leaves_torchs_threads_as_they_were():
    """``update_threads=1`` (a run sharing its cores): the same seed gives the same run, the
    driver's thread count is back after training, and every wall-clock part is recorded."""
    before = torch.get_num_threads()
    r1 = train(ENV, tiny(update_threads=1, n_workers=1))
    assert torch.get_num_threads() == before
    r2 = train(ENV, tiny(update_threads=1, n_workers=1))
    assert _learning_stats(r1.history) == _learning_stats(r2.history)
    _assert_same_model(_params(r1.model), _params(r2.model))
    assert len(r1.history["hook_s"]) == r1.iterations and r1.startup_s > 0 and r1.checkpoint_s == 0.0
    with pytest.raises(Exception, match=r"agent.update_threads=-1: must be an integer >= 0 \(0: torch's default\)"):
        tiny(update_threads=-1).check()
