"""``jt bench evaluation``: where one ``jt run``'s wall time goes, phase by phase.

``breakdown(overrides, store)`` runs ``jt run <overrides> store=<store>`` in a fresh process (so
its start is counted, as a user pays it), then reads from the store the ``wall_*_s`` metrics each
policy evaluation records (``toolkit.policy.history.time_breakdown``), its ``eval_seconds`` and
samples, and the wall time of any pose prior the run trained first (``action.prior=auto``).
``format_breakdown`` prints the table: each phase's seconds, its share of the command's wall time,
and samples per wall-second of the whole command and of its evaluations.

Phases (summed over the run's evaluations):

* ``collect``: PPO's rollouts (every worker stepping its envs: physics, SPD, the action space's
  decode, observations and rewards; ``jt bench rollout`` splits it further);
* ``update``: PPO's GAE and policy/value updates;
* ``hooks``: the task's per-iteration hook (a curriculum's deterministic test rollouts);
* ``checkpoint``: writing ``ppo.h5``;
* ``startup``: PPO's set-up before the first collection (the probe env, networks, workers);
* ``train, other``: the rest of training (the worker pool's start and close);
* ``final rollout``, ``pictures`` (its GIF and ``rollout.h5``), ``measure`` (the task's measures);
* ``evaluation, other``: the rest of each evaluation (environment spec, checkpoint loads);
* ``prior``: other runs the command made first (a pose prior trained on first use);
* ``outside evaluations``: process start, imports, composition, the store, the search and its
  summary (the command's wall time less everything above).
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Callable, Optional

from toolkit.errors import JtError

PARTS = ("startup", "collect", "update", "hooks", "checkpoint")
"""The parts of training each evaluation records as ``wall_<part>_s``."""
AFTER = ("final_rollout", "pictures", "measure")
"""The parts after training, ``wall_<part>_s``."""


def breakdown(overrides: list[str], store: Path, echo: Optional[Callable[[str], None]] = None) -> dict[str, Any]:
    """Run ``jt run <overrides> store=<store>`` in a fresh process and break its wall time down.

    Args:
        overrides: ``jt run``'s overrides (no ``store=``: ``store`` is used).
        store: the store folder (a kept one reuses its pose prior; a fresh one trains it).
        echo: where the run's own output lines go (None: discarded).

    Returns:
        ``{"command", "wall_s", "run_id", "evaluations", "samples", "phases": {name: seconds}}``.

    Raises:
        JtError: the run failed (its last line), or recorded no evaluation with a breakdown.
    """
    if any(o.startswith(("store=", "resume=")) for o in overrides):
        raise JtError("jt bench evaluation: give the store with --store, not store= (and no resume=)")
    command = [sys.executable, "-m", "toolkit.cli", "run", *overrides, f"store={store}"]
    env = {**os.environ, "JT_PROGRESS": os.environ.get("JT_PROGRESS", "lines")}
    t0 = time.time()
    started = time.perf_counter()
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    lines: list[str] = []
    assert proc.stdout is not None
    for line in proc.stdout:
        lines.append(line.rstrip("\n"))
        if echo is not None:
            echo("  | " + lines[-1].split("\r")[-1])
    rc = proc.wait()
    wall = time.perf_counter() - started
    if rc != 0:
        last = next((x for x in reversed(lines) if x.strip()), "(no output)")
        last = last.strip().removeprefix("jt: ")
        raise JtError(f"jt bench evaluation: jt run failed (exit {rc}): {last[:300]}")
    return {"command": "jt run " + " ".join(overrides), "wall_s": wall, **_read(store, t0 * 1000.0, wall)}


def _read(store: Path, since_ms: float, wall: float) -> dict[str, Any]:
    """The phases of the runs the command made in ``store`` (those started after ``since_ms``)."""
    from toolkit.store.opening import open_store

    client = open_store(store, must_exist=True).client
    ids = [e.experiment_id for e in client.search_experiments()]
    runs = client.search_runs(ids, filter_string=f"attributes.start_time >= {int(since_ms)}",
                              max_results=10000)
    evals = [r for r in runs if "wall_collect_s" in r.data.metrics]
    if not evals:
        raise JtError(f"jt bench evaluation: the run recorded no evaluation with a time breakdown in {store}")
    parents = {r.data.tags.get("mlflow.parentRunId") for r in evals} - {None}
    main = [r for r in runs if r.info.run_id in parents or (r in evals and "mlflow.parentRunId" not in r.data.tags)]
    mine = {r.info.run_id for r in evals} | {r.info.run_id for r in main}
    priors = [r for r in runs if r.info.run_id not in mine and r.info.end_time]  # e.g. a prior trained first
    phases: dict[str, float] = {}

    def add(name: str, seconds: float) -> None:
        phases[name] = phases.get(name, 0.0) + float(seconds)

    for r in evals:
        m = r.data.metrics
        parts = {p: float(m.get(f"wall_{p}_s", 0.0)) for p in PARTS}
        for p, s in parts.items():
            add(p, s)
        add("train, other", max(0.0, float(m["train_wall_s"]) - sum(parts.values())))
        after = {p: float(m.get(f"wall_{p}_s", 0.0)) for p in AFTER}
        for p, s in after.items():
            add(p.replace("_", " "), s)
        add("evaluation, other", max(0.0, float(m.get("eval_seconds", 0.0)) - float(m["train_wall_s"]) -
                                     sum(after.values())))
    prior = sum((r.info.end_time - r.info.start_time) / 1000.0 for r in priors)
    if prior:
        add("prior", prior)
    add("outside evaluations", max(0.0, wall - sum(phases.values())))
    samples = sum(float(r.data.metrics.get("samples", 0.0)) for r in evals)
    eval_s = sum(float(r.data.metrics.get("eval_seconds", 0.0)) for r in evals)
    run_id = main[0].info.run_id if main else evals[0].info.run_id
    return {"run_id": run_id, "evaluations": len(evals), "samples": samples, "eval_s": eval_s, "phases": phases}


def format_breakdown(res: dict[str, Any]) -> str:
    """The breakdown as a table: phase, seconds, share of the command's wall time; then samples per
    wall-second of the command and of its evaluations."""
    wall = float(res["wall_s"])
    order = ["startup", "collect", "update", "hooks", "checkpoint", "train, other", "final rollout", "pictures",
             "measure", "evaluation, other", "prior", "outside evaluations"]
    rows = [(name, res["phases"][name]) for name in order if name in res["phases"]]
    width = max(len(n) for n, _ in rows)
    out = [f"{res['command']}  (run {res['run_id']}, {res['evaluations']} evaluation(s), "
           f"{int(res['samples'])} samples)",
           f"{'phase':<{width}}  {'seconds':>9}  {'share':>6}"]
    out += [f"{name:<{width}}  {s:9.1f}  {100.0 * s / wall:5.1f}%" for name, s in rows]
    out.append(f"{'total (wall)':<{width}}  {wall:9.1f}  100.0%")
    samples = float(res["samples"])
    collect = res["phases"].get("collect", 0.0)
    out.append(f"samples/s: {samples / wall:.1f} per wall-second of the command, "
               f"{samples / max(res['eval_s'], 1e-9):.1f} of its evaluations, "
               f"{samples / max(collect, 1e-9):.1f} while collecting")
    return "\n".join(out)
