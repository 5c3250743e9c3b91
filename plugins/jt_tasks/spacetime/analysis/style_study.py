"""Style measures (hull volume, energy) of finished task=spacetime runs over their first seconds (002 §3.3).

A run logs ``style_energy`` / ``style_volume`` (and the reference's ``ref_*``) over its whole final
evaluation, which ends when the character falls; a fall changes both measures. This replays each
run's final policy (its ``ppo.h5`` and ``config.yaml`` artifacts, the deterministic rollout the run
itself made: same start, same seed) and measures the style over windows from the start, beside
the reference's at the same clip times, with the same estimators (``artifacts.style_measures``)::

    jt study spacetime style RUN_ID [RUN_ID ...] --store DIR --seconds 0.5 1 1.5

The last row of each run (window ``all``) is the whole evaluation: it equals the logged metrics.
"""

from __future__ import annotations

import math
from typing import Any, Optional, Sequence

from toolkit.errors import JtError, one_line_errors
from toolkit.study import parser

PROG = "jt study spacetime style"


def replay(config: Any, checkpoint: str) -> tuple[Any, Any]:
    """The final evaluation of a run with ``config`` (its composed config) and policy
    ``checkpoint`` (``ppo.h5``), replayed: the env (still open, holding ``eval_bodies``) and the
    rollout (a ``toolkit.policy.episodes.Rollout``)."""
    from toolkit.policy.episodes import rollout
    from toolkit import plugins
    from toolkit.rl.checkpoint import load_policy

    task = plugins.load("task", "spacetime")(config)
    env = task.env_class(task.env_spec({}), seed=0)
    ro = rollout(env, load_policy(checkpoint), task.record, 0, 160, 120, task.final_options(env))
    return env, ro


def windows(env: Any, ro: Any, seconds: Sequence[Optional[float]]) -> list[dict[str, float]]:
    """Per window (``None``: the whole evaluation): ``seconds``, ``steps`` (control steps measured),
    ``volume`` / ``ref_volume`` (m³), ``energy`` / ``ref_energy`` (J)."""
    from jt_tasks.spacetime.artifacts import reference_bodies, style_measures

    hz, bodies = float(env.control_hz), env.eval_bodies
    rows = []
    for w in seconds:
        n = len(bodies) if w is None else min(len(bodies), int(round(float(w) * hz)) + 1)
        pol = style_measures(bodies[:n], env.masses, hz)
        ref = style_measures(reference_bodies(env, ro.time[:n]), env.masses, hz)
        rows.append({"seconds": float("nan") if w is None else float(w), "steps": float(n),
                     "volume": pol["volume"], "ref_volume": ref["volume"],
                     "energy": pol["energy"], "ref_energy": ref["energy"]})
    return rows


def study(run_ids: Sequence[str], store: Optional[str], seconds: Sequence[float]) -> list[dict[str, Any]]:
    """``windows`` of every run in ``run_ids`` (``run``, ``survival_s`` added to each row)."""
    from omegaconf import OmegaConf

    from toolkit.store.opening import open_store
    from toolkit.store.tracking import store_root

    st = open_store(store_root(store), must_exist=True)
    arts = []
    for rid in run_ids:  # every run checked before the first replay
        run = st.get_run(rid)  # an unknown id is one JtError line
        task = run.data.tags.get("jt.task")
        if task != "spacetime":
            raise JtError(f"run {rid} is a {'task=' + task if task else 'non-jt'} run; "
                          f"{PROG} replays task=spacetime runs")
        art = st.artifact_dir(rid)
        if not (art / "ppo.h5").is_file() or not (art / "config.yaml").is_file():
            raise JtError(f"run {rid} has no ppo.h5 and config.yaml among its artifacts ({run.info.status}); "
                          f"{PROG} needs a finished run")
        arts.append((rid, art))
    out = []
    for rid, art in arts:
        env, ro = replay(OmegaConf.load(art / "config.yaml"), str(art / "ppo.h5"))
        try:
            for row in windows(env, ro, [*seconds, None]):
                out.append({"run": rid, "survival_s": float(ro.info["survival_s"]), **row})
        finally:
            env.close()
    return out


@one_line_errors
def main(argv: Optional[Sequence[str]] = None) -> None:
    ap = parser(PROG, __doc__.split("\n")[0])
    ap.add_argument("runs", nargs="+", help="run ids of finished spacetime runs")
    ap.add_argument("--store", default=None, help="the store (default: $JT_STORE, else ./artifacts)")
    ap.add_argument("--seconds", nargs="*", type=float, default=[0.5, 1.0, 1.5],
                    help="windows from the start, in seconds (default: 0.5 1 1.5); the whole evaluation is added")
    args = ap.parse_args(argv)
    bad = [w for w in args.seconds if not (math.isfinite(w) and w > 0)]
    if bad:
        raise JtError(f"--seconds={bad[0]}: a window is a finite number of seconds > 0 (e.g. --seconds 1)")
    rows = study(args.runs, args.store, args.seconds)  # errors before any output
    print("| run | survival (s) | window (s) | steps | volume / reference (m³) | energy / reference (J) |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        w = "all" if r["seconds"] != r["seconds"] else f"{r['seconds']:g}"
        print(f"| {r['run'][:8]} | {r['survival_s']:.2f} | {w} | {r['steps']:.0f} | {r['volume']:.4f} / "
              f"{r['ref_volume']:.4f} | {r['energy']:.2f} / {r['ref_energy']:.2f} |")


if __name__ == "__main__":
    main()
