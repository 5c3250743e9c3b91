"""PPO checkpoints as HDF5 files, written atomically.

Layout of a checkpoint file (every group written by ``write_tree``, which stores nested dicts,
lists, arrays, tensors and scalars losslessly and reads them back with their types)::

    /policy        policy-mean MLP state dict (tensors)
    /value         value MLP state dict
    /obs_norm      mean, std (what the networks use), count, sum, sumsq (running statistics)
    /policy_optim  the policy optimiser's state_dict (momentum buffers / Adam moments, step, lr...)
    /value_optim   the value optimiser's state_dict
    /counters      iteration, samples
    /rng           numpy (learner's minibatch generator, JSON), torch (CPU RNG state),
                   env_ids, seed and next seed_offset of the rollout workers
    /env_attrs     attributes last set on every environment (re-applied on resume)
    /extra         free-form caller state (e.g. a curriculum's)
    attrs: config (JSON of PPOConfig), obs_dim, act_dim, low, high, format, and warm_start
           (the checkpoint a warm-started run started from) if any

A **slim** checkpoint (``slim``: what a shipped skill holds, ``jt play``) keeps only ``/policy``,
``/obs_norm`` (mean, std) and ``/env_attrs`` with the attributes, plus ``slim``, ``samples`` and
``iteration``; ``load_policy`` reads both kinds.

``save`` writes ``<path>.tmp-<pid>``, fsyncs it and ``os.replace``s it onto ``path``
(``toolkit.store.atomic``), so a crash never leaves a half-written checkpoint behind.
(``toolkit.store.h5`` is not used: it reads back plain numpy dicts, while optimiser states need
int keys, tuples, None and tensors back exactly.)

The training glue (what ``toolkit.rl.ppo.train`` saves, resumes and warm-starts from) is at the
end: ``save_training``, ``load_training``, ``load_networks``, and for warm starts
``architecture_of``, ``with_architecture`` and ``load_warm_start``.
"""

from __future__ import annotations

import dataclasses
import json
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional

import h5py
import numpy as np
import torch

from toolkit.store.atomic import atomic_write

if TYPE_CHECKING:
    from toolkit.rl.config import PPOConfig
    from toolkit.rl.networks import ActorCritic, RunningObsStats

FORMAT = "jt.ppo.checkpoint/1"
_INT_KEY = "#int:"


def _key(k: Any) -> str:
    if isinstance(k, bool) or not isinstance(k, (str, int)):
        raise TypeError(f"checkpoint dict keys must be str or int, got {k!r}")
    if isinstance(k, int):
        return f"{_INT_KEY}{k}"
    if "/" in k or k.startswith(_INT_KEY) or k in (".", ""):
        raise ValueError(f"unsupported checkpoint key {k!r}")
    return k


def _unkey(k: str) -> Any:
    return int(k[len(_INT_KEY):]) if k.startswith(_INT_KEY) else k


def write_tree(parent: h5py.Group, name: str, obj: Any) -> None:
    """Store ``obj`` (dict / list / tuple / tensor / ndarray / scalar / str / None) at ``name``."""
    if isinstance(obj, dict):
        g = parent.create_group(name, track_order=True)
        g.attrs["kind"] = "dict"
        for k, v in obj.items():
            write_tree(g, _key(k), v)
    elif isinstance(obj, (list, tuple)):
        g = parent.create_group(name, track_order=True)
        g.attrs["kind"] = "list" if isinstance(obj, list) else "tuple"
        for i, v in enumerate(obj):
            write_tree(g, str(i), v)
    elif isinstance(obj, torch.Tensor):
        d = parent.create_dataset(name, data=obj.detach().cpu().numpy())
        d.attrs["kind"] = "tensor"
    elif isinstance(obj, np.ndarray):
        d = parent.create_dataset(name, data=obj)
        d.attrs["kind"] = "ndarray"
    elif obj is None:
        d = parent.create_dataset(name, data=h5py.Empty("f"))
        d.attrs["kind"] = "none"
    elif isinstance(obj, str):
        d = parent.create_dataset(name, data=obj, dtype=h5py.string_dtype())
        d.attrs["kind"] = "str"
    elif isinstance(obj, (bool, np.bool_)):
        d = parent.create_dataset(name, data=np.bool_(obj))
        d.attrs["kind"] = "bool"
    elif isinstance(obj, (int, np.integer)):
        d = parent.create_dataset(name, data=np.int64(obj))
        d.attrs["kind"] = "int"
    elif isinstance(obj, (float, np.floating)):
        d = parent.create_dataset(name, data=np.float64(obj))
        d.attrs["kind"] = "float"
    else:
        raise TypeError(f"cannot store {type(obj).__name__} in a checkpoint ({name})")


def read_tree(node: h5py.Group | h5py.Dataset) -> Any:
    """Inverse of ``write_tree``."""
    kind = node.attrs.get("kind", "dict" if isinstance(node, h5py.Group) else "ndarray")
    if kind == "dict":
        return {_unkey(k): read_tree(node[k]) for k in node.keys()}
    if kind in ("list", "tuple"):
        items = [read_tree(node[str(i)]) for i in range(len(node))]
        return items if kind == "list" else tuple(items)
    if kind == "tensor":
        return torch.from_numpy(np.array(node[()]))
    if kind == "ndarray":
        return np.array(node[()])
    if kind == "none":
        return None
    if kind == "str":
        v = node[()]
        return v.decode("utf-8") if isinstance(v, bytes) else str(v)
    if kind == "bool":
        return bool(node[()])
    if kind == "int":
        return int(node[()])
    if kind == "float":
        return float(node[()])
    raise ValueError(f"unknown node kind {kind!r} at {node.name}")


def save(path: str | os.PathLike, groups: dict[str, Any], attrs: dict[str, Any]) -> Path:
    """Write a checkpoint atomically.

    Args:
        path: target file.
        groups: top-level name -> tree (see the module docstring for the names PPO uses).
        attrs: file attributes (JSON-able values; dicts are stored as JSON strings).

    Returns:
        The written path.
    """
    path = Path(path)
    with atomic_write(path) as tmp:
        with h5py.File(tmp, "w", track_order=True) as f:
            f.attrs["format"] = FORMAT
            for k, v in attrs.items():
                f.attrs[k] = json.dumps(v) if isinstance(v, (dict, list)) else v
            for name, tree in groups.items():
                write_tree(f, name, tree)
    return path


def _decode_attrs(f: h5py.File, path: str | os.PathLike) -> dict[str, Any]:
    if f.attrs.get("format") != FORMAT:
        raise ValueError(f"{path}: not a jt PPO checkpoint (format {f.attrs.get('format')!r})")
    attrs: dict[str, Any] = {}
    for k, v in f.attrs.items():
        if isinstance(v, str) and v[:1] in "{[":
            v = json.loads(v)
        attrs[k] = v.tolist() if isinstance(v, np.ndarray) else v
    return attrs


def load(path: str | os.PathLike) -> tuple[dict[str, Any], dict[str, Any]]:
    """Read a checkpoint: ``(groups, attrs)`` as given to ``save`` (JSON attrs decoded)."""
    with h5py.File(path, "r") as f:
        attrs = _decode_attrs(f, path)
        groups = {k: read_tree(f[k]) for k in f.keys()}
    return groups, attrs


def load_attrs(path: str | os.PathLike) -> dict[str, Any]:
    """Only the attributes of a checkpoint (config, sizes, bounds), without reading the groups."""
    with h5py.File(path, "r") as f:
        return _decode_attrs(f, path)


def load_networks(groups: dict[str, Any], model: ActorCritic, obs_stats: Optional[RunningObsStats] = None) -> None:
    """Copy a checkpoint's policy, value network (when it has one) and observation normaliser
    into ``model``.

    Args:
        groups: ``load(path)[0]``.
        model: an ``ActorCritic`` of the checkpoint's sizes.
        obs_stats: also restore the normaliser's running statistics (count, sums) into this.
    """
    model.pi.load_state_dict(groups["policy"])
    if "value" in groups:  # a slim checkpoint (``slim``) has none: the value net stays as built
        model.v.load_state_dict(groups["value"])
    norm = groups["obs_norm"]
    model.norm.load_state_dict({"mean": torch.as_tensor(norm["mean"]), "std": torch.as_tensor(norm["std"])})
    if obs_stats is not None:
        obs_stats.load_state(norm)


def load_policy(path: str | os.PathLike) -> Any:
    """The trained ``ActorCritic`` (weights and observation normaliser) from a checkpoint, full or
    slim (``slim``: no value network, whose weights are then left as built)."""
    from toolkit.rl.networks import ActorCritic

    groups, attrs = load(path)
    cfg = attrs["config"]
    model = ActorCritic(
        int(attrs["obs_dim"]), int(attrs["act_dim"]), cfg["policy_hidden"], cfg["value_hidden"],
        np.asarray(attrs["low"]), np.asarray(attrs["high"]), cfg["normalize_actions"],
        None if attrs.get("out_scale") is None else np.asarray(attrs["out_scale"]),
    )
    load_networks(groups, model)
    return model


SLIM_GROUPS = ("policy", "obs_norm", "env_attrs")
"""What a slim checkpoint keeps: the policy, its observation normaliser (mean and std) and the
attributes last set on the environments (a curriculum's bar, control rate ...)."""


def slim(src: str | os.PathLike, dst: str | os.PathLike) -> Path:
    """Write ``dst``: the part of the PPO checkpoint ``src`` that acting needs (``SLIM_GROUPS``,
    the normaliser's mean and std only, every attribute), with ``slim = True`` and the training's
    ``samples`` and ``iteration`` as attributes. ``load_policy`` reads it and gives the same
    actions as from ``src``; training cannot resume from it (no value network, optimisers or
    RNG states). A 1024-512 policy: ~3 MB instead of ~16.

    Returns:
        ``dst``.
    """
    groups, attrs = load(src)
    missing = [g for g in ("policy", "obs_norm") if g not in groups]
    if missing:
        raise ValueError(f"{src}: no {', '.join(missing)} group (not a PPO checkpoint with a policy)")
    counters = groups.get("counters") or {}
    norm = groups["obs_norm"]
    kept = {"policy": groups["policy"], "obs_norm": {"mean": norm["mean"], "std": norm["std"]},
            "env_attrs": groups.get("env_attrs") or {}}
    attrs = {k: np.asarray(v) if k in ("low", "high", "out_scale") and v is not None else v
             for k, v in attrs.items() if k != "format"}
    attrs.update(slim=True, samples=int(counters.get("samples", attrs.get("samples", -1))),
                 iteration=int(counters.get("iteration", attrs.get("iteration", -1))))
    return save(dst, kept, attrs)


# ---------------------------------------------------------------------------- training glue
def save_training(
    path: Path,
    cfg: PPOConfig,
    model: ActorCritic,
    pi_opt: torch.optim.Optimizer,
    v_opt: torch.optim.Optimizer,
    obs_stats: RunningObsStats,
    rng: np.random.Generator,
    iteration: int,
    samples: int,
    history: dict[str, list[float]],
    env_attrs: dict[str, Any],
    extra: dict[str, Any],
    low: np.ndarray,
    high: np.ndarray,
    warm_start: Optional[str] = None,
) -> Path:
    """Write everything ``load_training`` needs to continue a run bit-identically.

    Args:
        path: the checkpoint file.
        cfg: the run's config (stored as the ``config`` attribute).
        model, pi_opt, v_opt, obs_stats, rng: the learner (networks, optimisers, normaliser
            statistics, minibatch generator); the torch CPU RNG state is saved too.
        iteration, samples: counters.
        history: per-iteration stats.
        env_attrs: attributes last set on every environment.
        extra: caller state.
        low, high: ``(act_dim,)`` action bounds.
        warm_start: the checkpoint the run was warm-started from (provenance attribute).

    Returns:
        ``path``.
    """
    mean, std = model.norm.mean.numpy(), model.norm.std.numpy()
    n_envs = cfg.n_workers * cfg.envs_per_worker
    attrs: dict[str, Any] = {"config": cfg.to_dict(), "obs_dim": model.obs_dim, "act_dim": model.act_dim,
                             "low": low, "high": high}
    if model.out_scale is not None:
        attrs["out_scale"] = model.out_scale
    if warm_start is not None:
        attrs["warm_start"] = str(warm_start)
    return save(path, {
        "policy": model.pi.state_dict(), "value": model.v.state_dict(),
        "obs_norm": {"mean": mean, "std": std, **obs_stats.state()},
        "policy_optim": pi_opt.state_dict(), "value_optim": v_opt.state_dict(),
        "counters": {"iteration": iteration, "samples": samples},
        "rng": {"numpy": json.dumps(rng.bit_generator.state), "torch": torch.get_rng_state(),
                "seed": cfg.seed, "env_ids": np.arange(n_envs), "seed_offset": iteration},
        "history": {k: np.asarray(v, dtype=np.float64) for k, v in history.items()},
        "env_attrs": env_attrs, "extra": extra,
    }, attrs)


def load_training(
    path: Path,
    model: ActorCritic,
    pi_opt: torch.optim.Optimizer,
    v_opt: torch.optim.Optimizer,
    obs_stats: RunningObsStats,
    rng: np.random.Generator,
) -> dict[str, Any]:
    """Restore a ``save_training`` checkpoint into the learner, in place (and the torch CPU RNG).

    Returns:
        ``iteration``, ``samples``, ``history`` (``{name: [float]}``), ``env_attrs``, ``extra``
        and ``warm_start`` (None unless the run was warm-started).
    """
    groups, attrs = load(path)
    load_networks(groups, model, obs_stats)
    pi_opt.load_state_dict(groups["policy_optim"])
    v_opt.load_state_dict(groups["value_optim"])
    rng.bit_generator.state = json.loads(groups["rng"]["numpy"])
    torch.set_rng_state(groups["rng"]["torch"])
    return {"iteration": groups["counters"]["iteration"], "samples": groups["counters"]["samples"],
            "history": {k: [float(x) for x in v] for k, v in groups["history"].items()},
            "env_attrs": groups["env_attrs"], "extra": groups["extra"],
            "warm_start": attrs.get("warm_start")}


def _jt_error(msg: str) -> Exception:
    from toolkit.errors import JtError

    return JtError(msg)


def architecture_of(path: str | os.PathLike) -> dict[str, Any]:
    """The network layout of a PPO checkpoint (what a warm start from it must match).

    Returns:
        ``policy_hidden`` and ``value_hidden`` (tuples of ints), ``normalize_actions`` (bool),
        ``obs_dim`` and ``act_dim`` (ints).

    Raises:
        toolkit.errors.JtError: ``path`` is missing or not a jt PPO checkpoint.
    """
    p = Path(path)
    if not p.is_file():
        raise _jt_error(f"warm start {p}: no such checkpoint file")
    try:
        attrs = load_attrs(p)
    except (OSError, ValueError) as e:
        raise _jt_error(f"warm start {p}: not a jt PPO checkpoint ({e})") from None
    c = attrs["config"]
    return {"policy_hidden": tuple(int(v) for v in c["policy_hidden"]),
            "value_hidden": tuple(int(v) for v in c["value_hidden"]),
            "normalize_actions": bool(c["normalize_actions"]),
            "obs_dim": int(attrs["obs_dim"]), "act_dim": int(attrs["act_dim"])}


def with_architecture(cfg: PPOConfig, path: str | os.PathLike) -> PPOConfig:
    """``cfg`` with the network sizes and action mapping of the checkpoint ``path`` (a copy).

    Everything else (learning rates, schedules, budget, seed...) stays ``cfg``'s.
    """
    arch = architecture_of(path)
    return dataclasses.replace(cfg, policy_hidden=arch["policy_hidden"], value_hidden=arch["value_hidden"],
                               normalize_actions=arch["normalize_actions"])


def load_warm_start(path: str | os.PathLike, cfg: PPOConfig, model: ActorCritic,
                    obs_stats: RunningObsStats) -> None:
    """Copy the policy, value network and observation normaliser (with its running statistics)
    of the checkpoint ``path`` into a fresh learner; optimisers, counters and RNGs stay fresh.

    Args:
        path: a PPO checkpoint of the same layout (see ``with_architecture``).
        cfg: the new run's config.
        model: the new run's freshly built ``ActorCritic`` (its sizes are the environment's).
        obs_stats: the new run's normaliser statistics.

    Raises:
        toolkit.errors.JtError: ``path`` is missing, not a checkpoint, or its observation/action
            sizes or network layout differ from the environment's / ``cfg``'s.
    """
    arch = architecture_of(path)
    if (arch["obs_dim"], arch["act_dim"]) != (model.obs_dim, model.act_dim):
        raise _jt_error(f"warm start {path}: its policy has observation/action sizes "
                        f"{arch['obs_dim']}/{arch['act_dim']}, this environment {model.obs_dim}/{model.act_dim}")
    mine = (tuple(int(h) for h in cfg.policy_hidden), tuple(int(h) for h in cfg.value_hidden),
            bool(cfg.normalize_actions))
    theirs = (arch["policy_hidden"], arch["value_hidden"], arch["normalize_actions"])
    if mine != theirs:
        def show(a: tuple) -> str:
            return f"policy_hidden={list(a[0])}, value_hidden={list(a[1])}, normalize_actions={str(a[2]).lower()}"

        raise _jt_error(f"warm start {path} has {show(theirs)}; the config {show(mine)} "
                        "(build it with toolkit.rl.with_architecture(cfg, path))")
    groups, _ = load(path)
    load_networks(groups, model, obs_stats)
