"""The training measurement of ``jt bench rollout``: a policy task trained for a few PPO iterations
exactly as ``jt run`` trains it (the task's own agent preset and networks, from an untrained
policy, in a temporary store), its speed read back from the evaluation's ``ppo.h5``: samples per
second with the updates included, and the shares of collection and update.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any, Callable, Optional, Sequence

import numpy as np


def cheap_overrides(cfg: Any) -> list[str]:
    """The task's own ``cheap_evaluation`` (``PolicyTask``) as overrides, for the keys its ``task``
    group has: they make what follows training cheap (no filmstrip, fewer or shorter measuring
    episodes) and change nothing that training does."""
    from toolkit import plugins
    from toolkit.config import group_of

    task = group_of(cfg, "task") or {}
    wanted = getattr(plugins.load("task", str(group_of(task, "name"))), "cheap_evaluation", {})
    return [f"task.{k}={v}" for k, v in wanted.items() if k in task]


def training(task: str, overrides: Sequence[str], n_workers: int, iterations: int,
             store_dir: Path | str, echo: Optional[Callable] = None) -> dict[str, Any]:
    """Train ``task`` for ``iterations`` PPO iterations exactly as ``jt run`` does, and read its speed.

    ``toolkit.execution.runner.run`` of ``task=<task> <overrides> <cheap_overrides>
    agent.n_workers=<n> agent.total_samples=<iterations * batch> store=<store_dir>``: the task's
    own agent preset and networks, from an untrained policy, episodes ending as training ends them;
    ``n_workers > 1`` runs the rollout workers in the executor's pool (``train_policy``). ``batch``
    is one iteration's samples, ``agent.samples_per_iteration`` rounded up to a multiple of the
    envs (``n_workers * agent.envs_per_worker``), as PPO collects them. Then the evaluation's
    ``ppo.h5`` is read (its ``history``: ``samples_per_s``, ``collect_s``, ``update_s``).

    Returns:
        ``n_workers``, ``iterations``, ``samples_per_iteration`` (the batch), ``agent`` (its
        preset's name), ``policy_hidden``, ``value_hidden``, ``overrides`` (all of them), the
        per-iteration lists ``samples_per_s``, ``collect_s``, ``update_s``, and over the
        iterations after the first (the first warms up: worker start, numba's cache; with one
        iteration it is used, and ``warmup_included`` says so) ``train_samples_per_s`` (samples /
        (collect + update)), ``collect_share`` and ``update_share`` (of collect + update),
        ``iterations_used``; ``wall_s`` (the whole ``run``: store, env spec, training, final
        rollout) and ``train_wall_s`` (the training alone, as the evaluation measured it).
    """
    import math

    import h5py

    from toolkit.config import compose, group_of
    from toolkit.execution.runner import run

    say = echo or (lambda s: None)
    n_workers, iterations = int(n_workers), int(iterations)
    base = compose([f"task={task}", *overrides])
    agent = group_of(base, "agent")
    n_envs = n_workers * int(agent.envs_per_worker)
    batch = n_envs * math.ceil(int(agent.samples_per_iteration) / n_envs)
    args = [f"task={task}", *overrides, *cheap_overrides(base), f"agent.n_workers={n_workers}",
            f"agent.total_samples={iterations * batch}", f"store={store_dir}"]
    cfg = compose(args)
    say(f"  training: jt run {' '.join(args)}")
    t0 = time.perf_counter()
    res = run(cfg, command=f"jt run {' '.join(args)}")
    wall = time.perf_counter() - t0
    art = res.store.artifact_dir(res.run_id)
    if not (art / "ppo.h5").exists():  # a search: the evaluation is the nested run
        kids = res.store.client.search_runs([res.store.client.get_run(res.run_id).info.experiment_id],
                                            filter_string=f"tags.mlflow.parentRunId = '{res.run_id}'")
        art = res.store.artifact_dir(kids[0].info.run_id)
    with h5py.File(art / "ppo.h5", "r") as f:
        hist = {k: [float(x) for x in np.asarray(f["history"][k][()], dtype=float).ravel()]
                for k in ("samples_per_s", "collect_s", "update_s")}
    sps, col, upd = hist["samples_per_s"], hist["collect_s"], hist["update_s"]
    first = 1 if len(sps) > 1 else 0
    samples = [s * (c + u) for s, c, u in zip(sps, col, upd)][first:]  # each iteration's batch
    c, u = float(np.sum(col[first:])), float(np.sum(upd[first:]))
    metrics = res.evaluations[0].metrics if res.evaluations else {}
    return {"n_workers": float(n_workers), "iterations": float(len(sps)), "samples_per_iteration": float(batch),
            "agent": str(group_of(agent, "name") or ""), "policy_hidden": [int(v) for v in agent.policy_hidden],
            "value_hidden": [int(v) for v in agent.value_hidden], "overrides": args[1:-1],
            "samples_per_s": sps, "collect_s": col, "update_s": upd,
            "iterations_used": float(len(sps) - first), "warmup_included": first == 0,
            "train_samples_per_s": float(np.sum(samples)) / (c + u) if c + u > 0 else float("nan"),
            "collect_share": c / (c + u) if c + u > 0 else float("nan"),
            "update_share": u / (c + u) if c + u > 0 else float("nan"),
            "wall_s": wall, "train_wall_s": float(metrics.get("train_wall_s", float("nan")))}
