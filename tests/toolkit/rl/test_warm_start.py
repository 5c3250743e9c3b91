"""Warm starts: ``train(..., warm_start=)`` is a fresh run with another run's networks.

The reference is the recipe Stage 2 used before this API (write a fresh-run checkpoint holding the
init policy, then resume it); the warm start must reproduce it bit for bit.
"""

import dataclasses
import json

import numpy as np
import pytest
import torch

from toolkit.errors import JtError
from toolkit.rl import architecture_of, with_architecture
from toolkit.rl import checkpoint as ckpt
from toolkit.rl import ppo
from toolkit.rl.networks import ActorCritic
from toolkit.rl.ppo import PPOConfig, train
from toolkit.rl.sanity import GymEnvFn
from toolkit.rl.ppo import TIMING as ppo_timing

ENV = GymEnvFn("Pendulum-v1", max_episode_steps=50)
TIMING = set(ppo_timing)  # wall-clock keys: they differ between identical runs


def small(**kw) -> PPOConfig:
    base = dict(policy_hidden=(24, 16), value_hidden=(20,), samples_per_iteration=128, minibatch_size=64,
                epochs=2, policy_lr=1e-3, value_lr=1e-3, std_anneal_samples=1024, total_samples=2 * 128,
                n_workers=2, envs_per_worker=2, checkpoint_every=2, seed=1)
    base.update(kw)
    return PPOConfig(**base)


def gravity(it, samples, stats):
    return {"g": 10.0 - 0.5 * it}


@pytest.fixture(scope="module")
def source(tmp_path_factory):
    """A trained 'Stage-1' checkpoint (other nets and seed than the runs below use by default)."""
    path = tmp_path_factory.mktemp("src") / "stage1.h5"
    train(ENV, small(normalize_actions=True), checkpoint_path=path, on_iteration=gravity)
    return path


def _legacy_warm_start(path, init, cfg, env_fn, extra):
    """Stage 2's former ``write_warm_start``: a fresh-run checkpoint with ``init``'s networks."""
    groups, attrs = ckpt.load(init)
    obs_dim, act_dim, low, high, _ = ppo._probe(env_fn, cfg.seed)
    torch.manual_seed(cfg.seed)
    model = ActorCritic(obs_dim, act_dim, cfg.policy_hidden, cfg.value_hidden, low, high, cfg.normalize_actions)
    pi_opt = ppo._make_optimizer(model.pi.parameters(), cfg.policy_lr, cfg)
    v_opt = ppo._make_optimizer(model.v.parameters(), cfg.value_lr, cfg)
    rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([cfg.seed, 3])))
    ckpt.save(path, {
        "policy": groups["policy"], "value": groups["value"], "obs_norm": groups["obs_norm"],
        "policy_optim": pi_opt.state_dict(), "value_optim": v_opt.state_dict(),
        "counters": {"iteration": 0, "samples": 0},
        "rng": {"numpy": json.dumps(rng.bit_generator.state), "torch": torch.get_rng_state(),
                "seed": cfg.seed, "env_ids": np.arange(cfg.n_workers * cfg.envs_per_worker), "seed_offset": 0},
        "history": {}, "env_attrs": {}, "extra": dict(extra),
    }, {"config": cfg.to_dict(), "obs_dim": obs_dim, "act_dim": act_dim, "low": low, "high": high})


def _same(a, b, where=""):
    if isinstance(a, dict):
        assert list(a) == list(b), where
        for k in a:
            _same(a[k], b[k], f"{where}/{k}")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{where}[{i}]")
    elif isinstance(a, torch.Tensor):
        assert torch.equal(a, b), where
    elif isinstance(a, np.ndarray):
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), where
    else:
        assert a == b or (a != a and b != b), (where, a, b)


def _learning(groups):
    groups = dict(groups)
    groups["history"] = {k: v for k, v in groups["history"].items() if k not in TIMING}
    return groups


def test_architecture_of_and_with_architecture(source):
    assert architecture_of(source) == {"policy_hidden": (24, 16), "value_hidden": (20,),
                                       "normalize_actions": True, "obs_dim": 3, "act_dim": 1}
    cfg = PPOConfig(policy_lr=3e-4, target_kl=0.02, seed=9)
    new = with_architecture(cfg, source)
    assert (new.policy_hidden, new.value_hidden, new.normalize_actions) == ((24, 16), (20,), True)
    assert dataclasses.replace(new, policy_hidden=cfg.policy_hidden, value_hidden=cfg.value_hidden,
                               normalize_actions=cfg.normalize_actions) == cfg
    assert cfg.policy_hidden == (1024, 512)  # a copy: the input is unchanged


@pytest.mark.parametrize("optimizer", ["sgd", "adam"])
def test_warm_start_reproduces_the_legacy_checkpoint_recipe(tmp_path, source, optimizer):
    cfg = with_architecture(small(seed=4, optimizer=optimizer, total_samples=3 * 128), source)
    legacy_path, new_path = tmp_path / "legacy.h5", tmp_path / "new.h5"
    legacy_extra, new_extra = {"cur": {"level": 2, "acc": 0.25}}, {"cur": {"level": 2, "acc": 0.25}}
    _legacy_warm_start(legacy_path, source, cfg, ENV, legacy_extra)
    legacy = train(ENV, cfg, checkpoint_path=legacy_path, on_iteration=gravity, extra=legacy_extra)
    new = train(ENV, cfg, checkpoint_path=new_path, on_iteration=gravity, extra=new_extra, warm_start=source)
    assert new.iterations == legacy.iterations == 3 and new_extra == legacy_extra
    _same({k: v for k, v in new.history.items() if k not in TIMING},
          {k: v for k, v in legacy.history.items() if k not in TIMING})
    _same(new.model.state_dict(), legacy.model.state_dict())
    # the whole checkpoint (optimiser moments, RNG states, normaliser sums) is the same
    _same(_learning(ckpt.load(new_path)[0]), _learning(ckpt.load(legacy_path)[0]))
    assert ckpt.load_attrs(new_path)["warm_start"] == str(source)


def test_zero_budget_keeps_the_source_networks_and_statistics(tmp_path, source):
    path = tmp_path / "ppo.h5"
    res = train(ENV, with_architecture(small(seed=8, total_samples=0), source), checkpoint_path=path,
                warm_start=source)
    src, got = ckpt.load(source)[0], ckpt.load(path)[0]
    assert res.iterations == 0 and res.history == {} and got["counters"] == {"iteration": 0, "samples": 0}
    _same(got["policy"], src["policy"])
    _same(got["value"], src["value"])
    _same(got["obs_norm"], src["obs_norm"])
    assert got["obs_norm"]["count"] == 2 * 128  # the running statistics came along
    assert got["policy_optim"]["state"] == {} and got["env_attrs"] == {}  # fresh optimiser, no attrs
    fresh = train(ENV, with_architecture(small(seed=8, total_samples=0), source))
    assert not torch.equal(fresh.model.pi[0].weight, res.model.pi[0].weight)


def test_an_existing_checkpoint_is_resumed_and_the_warm_start_ignored(tmp_path, source):
    cfg = with_architecture(small(total_samples=4 * 128), source)
    whole = train(ENV, cfg, warm_start=source, on_iteration=gravity)
    path = tmp_path / "ppo.h5"
    train(ENV, dataclasses.replace(cfg, total_samples=2 * 128), checkpoint_path=path, warm_start=source,
          on_iteration=gravity)
    # the warm start would now fail (it does not exist), but it is not read: the run resumes
    resumed = train(ENV, cfg, checkpoint_path=path, warm_start=tmp_path / "gone.h5", on_iteration=gravity)
    assert resumed.iterations == 4
    _same({k: v for k, v in resumed.history.items() if k not in TIMING},
          {k: v for k, v in whole.history.items() if k not in TIMING})
    _same(resumed.model.state_dict(), whole.model.state_dict())
    assert ckpt.load_attrs(path)["warm_start"] == str(source)  # provenance survives the resume


def test_warm_start_errors_are_one_line(tmp_path, source):
    cfg = with_architecture(small(), source)
    with pytest.raises(JtError, match=r"observation/action sizes 3/1, this environment 2/1$"):
        train(GymEnvFn("MountainCarContinuous-v0", max_episode_steps=20), cfg, warm_start=source)
    with pytest.raises(JtError, match=r"policy_hidden=\[24, 16\].*the config policy_hidden=\[24, 16\], "
                                      r"value_hidden=\[20\], normalize_actions=false.*with_architecture"):
        train(ENV, dataclasses.replace(cfg, normalize_actions=False), warm_start=source)
    with pytest.raises(JtError, match=r"^warm start .*gone\.h5: no such checkpoint file$"):
        train(ENV, cfg, warm_start=tmp_path / "gone.h5")
    junk = tmp_path / "junk.h5"
    junk.write_text("not hdf5")
    with pytest.raises(JtError, match=r"^warm start .*junk\.h5: not a jt PPO checkpoint"):
        architecture_of(junk)
