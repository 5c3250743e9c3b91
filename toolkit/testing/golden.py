"""Seeded env trajectories, recorded once and held to the last digit (golden tests).

A speed change to an environment must not change what it computes. ``trajectory`` runs an env
for ``n_steps`` control steps of seeded random actions (``N(0, 0.3²)`` of the half range around the
action space's centre, as ``jt bench rollout``), resetting when an episode ends, and returns every
observation, reward, termination, truncation and numeric ``info`` value (resets' included) as
flat arrays, plus the episode-end reasons. ``compare`` holds one trajectory against another.

The last digits depend on the machine (numpy's SIMD kernels, the PyBullet build), so a recording
is named by ``machine_key`` and made on the commit *before* a change (``JT_RECORD_GOLDEN=1``);
a machine without its own recording is held loosely to the first control steps of another.
"""

from __future__ import annotations

import hashlib
import platform
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np


def machine_key() -> str:
    """A short hash of what the last digits depend on: CPU model, numpy's enabled SIMD features,
    torch's CPU capability, numpy's and torch's versions (the PPO goldens' key, the same string)."""
    import torch

    cpu = platform.processor()
    if Path("/proc/cpuinfo").exists():
        cpu = next((ln.split(":", 1)[1].strip() for ln in Path("/proc/cpuinfo").read_text().splitlines()
                    if ln.startswith("model name")), cpu)
    core = getattr(np, "_core", None) or np.core
    feats = sorted(k for k, v in core._multiarray_umath.__cpu_features__.items() if v)
    text = "|".join([platform.machine(), cpu, str(torch.backends.cpu.get_cpu_capability()), np.__version__,
                     torch.__version__, ",".join(feats)])
    return hashlib.sha1(text.encode()).hexdigest()[:10]


def trajectory(env: Any, n_steps: int, seed: int = 0, options: Optional[Callable[[int], Optional[dict]]] = None,
               extra: Optional[Callable[[Any], Optional[np.ndarray]]] = None) -> dict[str, Any]:
    """``n_steps`` seeded random-action control steps of ``env``, resets included.

    Args:
        env: a ``gymnasium.Env``; reset with ``seed`` first, then without a seed after each end.
        options: ``options(k)`` gives the reset options of the ``k``-th reset (None: none).
        extra: ``extra(env)`` after every step, an array recorded as ``extra`` (e.g. a state the
            env reports to its learner); None entries are recorded as NaN of the first's shape.

    Returns:
        ``obs`` ``(n_steps + n_resets, obs_dim)`` (every reset's and step's observation, in order),
        ``reward``, ``terminated``, ``truncated`` ``(n_steps,)``, ``info/<key>`` ``(n_rows,)``
        (NaN where a row lacks the key; rows as ``obs``), ``extra`` ``(n_steps, d)``, and
        ``reasons`` (the episode-end reasons, a list of str).
    """
    rng = np.random.default_rng(seed)
    low, high = env.action_space.low.astype(np.float64), env.action_space.high.astype(np.float64)
    mid, half = 0.5 * (low + high), 0.5 * (high - low)
    obs_rows, infos, rewards, terms, truncs, extras, reasons = [], [], [], [], [], [], []
    resets = 0
    obs, info = env.reset(seed=seed, options=options(0) if options else None)
    obs_rows.append(obs)
    infos.append(info)
    for _ in range(n_steps):
        a = np.clip(mid + 0.3 * half * rng.standard_normal(mid.shape), low, high).astype(np.float32)
        obs, r, te, tr, info = env.step(a)
        obs_rows.append(obs)
        infos.append(info)
        rewards.append(r)
        terms.append(te)
        truncs.append(tr)
        if extra is not None:
            extras.append(extra(env))
        if te or tr:
            reasons.append(str(info.get("reason", "")))
            resets += 1
            obs, info = env.reset(options=options(resets) if options else None)
            obs_rows.append(obs)
            infos.append(info)
    out: dict[str, Any] = {"obs": np.asarray(obs_rows, dtype=np.float64), "reward": np.asarray(rewards, float),
                           "terminated": np.asarray(terms, float), "truncated": np.asarray(truncs, float),
                           "reasons": reasons}
    keys = sorted({k for i in infos for k, v in i.items() if isinstance(v, (int, float, np.number))})
    for k in keys:
        out[f"info/{k}"] = np.array([float(i[k]) if k in i else np.nan for i in infos])
    if extra is not None:
        shape = next((np.shape(e) for e in extras if e is not None), (0,))
        out["extra"] = np.array([np.full(shape, np.nan) if e is None else np.asarray(e, float) for e in extras])
    return out


def save(path: Path, traj: dict[str, Any]) -> None:
    """Write a trajectory as a compressed ``.npz`` (reasons as a string array)."""
    arrays = {k: v for k, v in traj.items() if k != "reasons"}
    np.savez_compressed(path, reasons=np.array(traj["reasons"], dtype=str), **arrays)


def load(path: Path) -> dict[str, Any]:
    """A trajectory written by ``save``."""
    with np.load(path) as z:
        out = {k: z[k] for k in z.files}
    out["reasons"] = [str(s) for s in out["reasons"]]
    return out


def compare(got: dict[str, Any], want: dict[str, Any], rtol: float = 1e-9, atol: float = 1e-12,
            rows: Optional[int] = None) -> None:
    """Assert ``got`` equals ``want``: the same keys, every array to ``rtol``/``atol`` (NaN where
    NaN), the same reasons; ``rows``: only the first rows of each (a loose check elsewhere).

    Raises:
        AssertionError: naming the first key that differs.
    """
    assert sorted(k for k in got if k != "reasons") == sorted(k for k in want if k != "reasons"), \
        f"keys differ: {sorted(set(got) ^ set(want))}"
    for k in want:
        if k == "reasons":
            continue
        a, b = np.asarray(got[k]), np.asarray(want[k])
        if rows is not None:
            a, b = a[:rows], b[:rows]
        assert a.shape == b.shape, f"{k}: shape {a.shape} != recorded {b.shape}"
        np.testing.assert_allclose(a, b, rtol=rtol, atol=atol, equal_nan=True, err_msg=k)
    if rows is None:
        assert got["reasons"] == want["reasons"], f"episode-end reasons differ: {got['reasons']} != {want['reasons']}"
