"""RMOO vs BSOO vs random search on the standing jump: hypervolume against simulations, final fronts.

Drives the searchers' ``ask``/``tell`` directly (no runner, no MLflow) with a process pool, and
records the hypervolume of all successful samples so far after every evaluation (``004`` §5
compares the fronts the two algorithms find, Fig. 8)::

    jt study standing_jump hypervolume --budget 192 --seeds 0 --workers 2 --out study

writes ``study/study.json`` (curves, final fronts) and ``study/hypervolume.png``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Optional, Sequence

import numpy as np

from toolkit.errors import JtError, one_line_errors
from toolkit.study import parser, writable_folder

PROG = "jt study standing_jump hypervolume"

SEARCHERS = {  # label: (registry name, search config)
    # 004 §4.3 / §5: mu = 16, at most 3 failed children per generation
    "rmoo": ("rmoo", {"batch": 16, "mu": 16, "sigma0": 0.015, "max_failed": 3}),
    # the same with Voss et al. (2010)'s success rule (not the paper's)
    "rmoo_selected": ("rmoo", {"batch": 16, "mu": 16, "sigma0": 0.015, "max_failed": 3,
                                                         "success": "selected"}),
    # 004 §4.1 as configured by default: 16 bins, 16 offspring, sigma0 0.015, the budget shared by the bins
    "bsoo": ("bsoo", {}),
    # BSOO re-tuned to a small budget (ours): 4 bins of head height over 1.6-2.4 m, 8 offspring
    "bsoo_4bins": ("bsoo", {"batch": 8, "popsize": 8, "n_bins": 4, "sigma0": 0.015,
                                                      "bin_low": -2.4, "bin_high": -1.6}),
    "random": ("random", {"batch": 16}),
}


def _load(name: str) -> type:
    """A searcher class through the registry (a plugin never imports another plugin)."""
    from toolkit import plugins

    return plugins.load("search", name)


def _evaluate(args: tuple[dict, int]) -> Any:
    from jt_tasks.standing_jump.task import StandingJumpTask
    from toolkit.interfaces.task import EvalContext

    point, index = args
    task = StandingJumpTask({"task": {"save_trajectory": False, "filmstrips": False}})
    return task.evaluate(point, EvalContext(index=index, seed=index, workdir=Path(".")))


def run_one(name: str, budget: int, seed: int, pool: Any) -> dict[str, Any]:
    """One search; returns the hypervolume after each evaluation and the evaluations' objectives."""
    from jt_tasks.standing_jump.objectives import hypervolume
    from jt_tasks.standing_jump.task import StandingJumpTask

    task = StandingJumpTask({"task": {"save_trajectory": False, "filmstrips": False}})
    problem = task.problem()
    ref = problem.reference_point
    path, cfg = SEARCHERS[name]
    s = _load(path)(problem, {**cfg, "budget": budget}, seed)
    F, ok, natural, hv = [], [], [], []
    while not s.finished() and len(F) < budget:
        X = s.ask(int(s.cfg.batch))
        if len(X) == 0:
            break
        evs = pool.map(_evaluate, [(problem.space.to_dict(x), len(F) + i) for i, x in enumerate(X)])
        s.tell(X, evs)
        for e in evs:
            F.append(list(e.objectives))
            ok.append(not e.failed)
            natural.append(bool(e.metrics.get("natural", 0.0)))
            Fa, oka = np.array(F), np.array(ok)
            hv.append(hypervolume(Fa, ref, valid=oka))
    return {"searcher": name, "seed": seed, "hypervolume": hv, "objectives": F, "success": ok,
            "natural": natural, "reference_point": list(ref)}


def plot(results: Sequence[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from jt_tasks.standing_jump.objectives import non_dominated

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    colours = {"rmoo": "tab:green", "rmoo_selected": "tab:olive", "bsoo": "tab:red", "bsoo_4bins": "tab:orange",
               "random": "tab:gray"}
    for r in results:
        a1.plot(np.arange(1, len(r["hypervolume"]) + 1), r["hypervolume"], c=colours[r["searcher"]],
                label=f"{r['searcher']} (seed {r['seed']})")
        F, ok = np.array(r["objectives"]), np.array(r["success"])
        if ok.any():
            nd = non_dominated(F, valid=ok)
            idx = np.flatnonzero(nd)
            idx = idx[np.argsort(-F[idx, 0])]
            a2.plot(-F[idx, 0], F[idx, 1], "o-", c=colours[r["searcher"]], ms=4, label=r["searcher"])
    a1.set_xlabel("simulations")
    a1.set_ylabel("hypervolume of successful samples")
    a1.legend(fontsize=7)
    a2.set_xlabel("head apex height (m)")
    a2.set_ylabel("log(w_JE e_JE + w_SE e_SE)")
    a2.set_title("final fronts", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


@one_line_errors
def main(argv: Optional[Sequence[str]] = None) -> None:
    import multiprocessing as mp

    ap = parser(PROG, __doc__.split("\n")[0])
    ap.add_argument("--budget", type=int, default=192, help="simulations per search (default 192)")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0], help="one search per searcher and seed (default 0)")
    ap.add_argument("--searchers", nargs="+", default=["rmoo", "bsoo", "random"], choices=list(SEARCHERS),
                    help="which searchers (default: rmoo bsoo random)")
    ap.add_argument("--workers", type=int, default=2, help="processes simulating side by side (default 2)")
    ap.add_argument("--out", type=str, default="study", help="folder for study.json and hypervolume.png")
    a = ap.parse_args(argv)
    if a.budget < 1:
        raise JtError(f"--budget={a.budget}: at least 1 simulation")
    if a.workers < 1:
        raise JtError(f"--workers={a.workers}: at least 1 process")
    out = writable_folder(a.out, "--out")
    results = []
    with mp.Pool(a.workers) as pool:
        for seed in a.seeds:
            for name in a.searchers:
                r = run_one(name, a.budget, seed, pool)
                results.append(r)
                print(f"{name:7s} seed {seed}: {len(r['hypervolume'])} sims, {sum(r['success'])} successful, "
                      f"final hypervolume {r['hypervolume'][-1] if r['hypervolume'] else 0.0:.3f}", flush=True)
                (out / "study.json").write_text(json.dumps(results))
    plot(results, out / "hypervolume.png")


if __name__ == "__main__":
    main()
