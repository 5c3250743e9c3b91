"""Which bound a trained task=spacetime policy leaves first, and when: Table 1's evaluation, bounds watched.

Issue 28: a ``task=spacetime`` run's deterministic policy (its ``ppo.h5``) is played from ``starts`` start
phases spread evenly from 0, as Table 1's evaluation does (bounds off: only a forbidden ground
contact or the 20 s limit ends the episode), and after every control step the 22-channel
difference to the reference is checked against the bounds the run trained under. Per start: the
seconds survived, the first channels to leave their bounds (with the time), and each channel's
largest ``|difference| / width`` over the episode. A policy that walks 20 s but leaves a bound at
1 s would have had every training episode cut there::

    jt study spacetime policy-bounds RUN --store DIR [--starts 4] [--seconds 20]

``RUN`` is a run id (the store's), a folder holding ``ppo.h5`` or the file; the run's
``config.yaml`` beside it gives the task (``--config`` to name another).
"""

from __future__ import annotations

import math
from typing import Any, Optional, Sequence

import numpy as np

from toolkit.errors import JtError, one_line_errors
from toolkit.study import parser

PROG = "jt study spacetime policy-bounds"


def watch(env: Any, policy: Any, phase: float, max_steps: Optional[int] = None) -> dict[str, Any]:
    """One evaluation episode of ``policy`` from ``phase`` with the bounds watched.

    Args:
        env: a ``SpacetimeEnv``.
        policy: anything with ``act(obs) -> (act_dim,)`` (the trained ``ActorCritic``).
        phase: the start phase in ``[0, 1)``.
        max_steps: control steps at most (None: until the evaluation ends the episode).

    Returns:
        ``seconds`` (survived), ``first`` (``{channel: seconds}`` of each channel's first
        violation), ``peak`` ``(n_channels,)`` (largest ``|difference| / width``; 0 for a channel
        that is off).
    """
    from jt_tasks.spacetime import bounds as bd

    obs, _ = env.reset(seed=0, options={"phase": float(phase), "evaluate": True})
    first: dict[str, float] = {}
    peak = np.zeros(len(env.names))
    steps = 0
    while max_steps is None or steps < max_steps:
        obs, _, te, tr, _ = env.step(np.asarray(policy.act(obs), dtype=np.float32))
        steps += 1
        d, w = env.difference(), env.widths_at(env.ref.phase(env.clip_time))
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(np.isfinite(w), np.abs(d) / w, 0.0)
        peak = np.maximum(peak, ratio)
        for name in bd.violations(d, w, env.names):
            first.setdefault(name, steps / env.control_hz)
        if te or tr:
            break
    return {"seconds": steps / env.control_hz, "first": first, "peak": peak}


def report(rows: Sequence[dict[str, Any]], names: Sequence[str], phases: Sequence[float], top: int = 3) -> list[str]:
    """Markdown lines: per start its seconds, the first ``top`` violations and the largest ratios."""
    out = ["| start phase | survived (s) | first bounds left (s) | largest abs(difference) / width |", "|---|---|---|---|"]
    for ph, r in zip(phases, rows):
        firsts = ", ".join(f"{c} {t:.2f}" for c, t in sorted(r["first"].items(), key=lambda x: x[1])[:top]) or "none"
        order = np.argsort(-r["peak"])[:top]
        peaks = ", ".join(f"{names[i]} {r['peak'][i]:.2f}" for i in order)
        out.append(f"| {ph:.3f} | {r['seconds']:.2f} | {firsts} | {peaks} |")
    return out


@one_line_errors
def main(argv: Optional[Sequence[str]] = None) -> None:
    from omegaconf import OmegaConf

    from toolkit import plugins
    from toolkit.config import validate
    from toolkit.rl.checkpoint import load_policy
    from toolkit.store.resolve import resolve, run_config

    ap = parser(PROG, __doc__.split("\n")[0])
    ap.add_argument("run", help="a task=spacetime run id, a folder holding ppo.h5, or the file")
    ap.add_argument("--store", default=None, help="the store the run is in")
    ap.add_argument("--config", default=None, help="the run's config.yaml (default: the one beside its ppo.h5)")
    ap.add_argument("--starts", type=int, default=4, help="start phases k / starts (default 4, Table 1's evaluation)")
    ap.add_argument("--seconds", type=float, default=None, help="seconds per episode at most (default: the run's)")
    args = ap.parse_args(argv)
    if args.starts < 1:
        raise JtError(f"--starts={args.starts}: at least 1 start phase")
    if args.seconds is not None and not (math.isfinite(args.seconds) and args.seconds > 0):
        raise JtError(f"--seconds={args.seconds}: a finite number of seconds > 0 (e.g. --seconds 20)")
    ref = resolve(args.run, artifact="ppo.h5", store=args.store, what="run", label="trained policy")
    cfg = validate(OmegaConf.load(run_config(ref.path, args.config)))
    if cfg.task.name != "spacetime":
        raise JtError(f"{args.run}: a task={cfg.task.name} run; {PROG} reads task=spacetime runs")
    env = plugins.load("task", "spacetime")(cfg).make_env(None, seed=0)
    try:
        policy = load_policy(ref.path)
        limit = None if args.seconds is None else int(round(args.seconds * env.control_hz))
        phases = [k / args.starts for k in range(args.starts)]
        rows = [watch(env, policy, ph, limit) for ph in phases]
        names = list(env.names)
    finally:
        env.close()
    print("\n".join(report(rows, names, phases)))


if __name__ == "__main__":
    main()
