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
    attrs: config (JSON of PPOConfig), obs_dim, act_dim, low, high, format

``save`` writes ``path.tmp``, fsyncs it and ``os.replace``s it onto ``path``, so a crash never
leaves a half-written checkpoint behind. (``toolkit.store.h5`` is not used: it reads back plain
numpy dicts, while optimiser states need int keys, tuples, None and tensors back exactly.)
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import h5py
import numpy as np
import torch

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
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    with h5py.File(tmp, "w", track_order=True) as f:
        f.attrs["format"] = FORMAT
        for k, v in attrs.items():
            f.attrs[k] = json.dumps(v) if isinstance(v, (dict, list)) else v
        for name, tree in groups.items():
            write_tree(f, name, tree)
    with open(tmp, "rb") as fh:  # on disk before the rename
        os.fsync(fh.fileno())
    os.replace(tmp, path)
    return path


def load(path: str | os.PathLike) -> tuple[dict[str, Any], dict[str, Any]]:
    """Read a checkpoint: ``(groups, attrs)`` as given to ``save`` (JSON attrs decoded)."""
    with h5py.File(path, "r") as f:
        if f.attrs.get("format") != FORMAT:
            raise ValueError(f"{path}: not a jt PPO checkpoint (format {f.attrs.get('format')!r})")
        attrs: dict[str, Any] = {}
        for k, v in f.attrs.items():
            if isinstance(v, str) and v[:1] in "{[":
                v = json.loads(v)
            attrs[k] = v.tolist() if isinstance(v, np.ndarray) else v
        groups = {k: read_tree(f[k]) for k in f.keys()}
    return groups, attrs


def load_policy(path: str | os.PathLike) -> Any:
    """The trained ``ActorCritic`` (weights and observation normaliser) from a checkpoint."""
    from toolkit.rl.networks import ActorCritic

    groups, attrs = load(path)
    cfg = attrs["config"]
    model = ActorCritic(
        int(attrs["obs_dim"]), int(attrs["act_dim"]), cfg["policy_hidden"], cfg["value_hidden"],
        np.asarray(attrs["low"]), np.asarray(attrs["high"]), cfg["normalize_actions"],
    )
    model.pi.load_state_dict(groups["policy"])
    model.v.load_state_dict(groups["value"])
    norm = groups["obs_norm"]
    model.norm.load_state_dict({"mean": torch.as_tensor(norm["mean"]), "std": torch.as_tensor(norm["std"])})
    return model
