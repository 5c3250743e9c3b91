"""Quality benchmarks of the searchers (the numbers in docs/searchers.md).

    PYTHONPATH=.:plugins python tests/plugins/jt_searchers/bench_searchers.py distinct --seeds 20
    PYTHONPATH=.:plugins python tests/plugins/jt_searchers/bench_searchers.py zdt --seeds 5 --budgets 500 1000 2000 5000

``distinct``: distinct strategies found in the first ``n`` samples on ``strategy_landscape`` (BDS vs
random, ``000`` §7.2.1). ``zdt``: hypervolume ratio on ZDT1 at equal budgets (RMOO vs BSOO vs
random, ``004`` §5). Runs are spread over ``--jobs`` processes; every run is seeded.
"""

from __future__ import annotations

import argparse
import os
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

sys.path[:0] = [str(Path(__file__).parent)]

from searcher_loop import run_search  # noqa: E402

LANDSCAPES = {
    "default": {},
    "more unequal (latent_scale=0.08)": {"latent_scale": 0.08},
    "latent_scale=0.15": {"latent_scale": 0.15},
    "less unequal (latent_scale=0.2)": {"latent_scale": 0.2},
    "landscape_seed=1": {"landscape_seed": 1},
    "landscape_seed=2": {"landscape_seed": 2},
    "1 feature": {"n_features": 1, "min_separation": 0.06, "distinct_threshold": 0.03, "noise": 0.005},
    "voronoi (no spatial structure)": {"layout": "voronoi", "latent_scale": 0.35},
}

SEARCHERS = {
    "bds": ("jt_searchers.bds:BDSSearcher", {}),
    "bds batch=4": ("jt_searchers.bds:BDSSearcher", {"batch": 4}),
    "bds explore only (n_opt=0)": ("jt_searchers.bds:BDSSearcher", {"n_opt": 0}),
    "bds diversity only (n_exp=0)": ("jt_searchers.bds:BDSSearcher", {"n_exp": 0}),
    "bds n_init=1": ("jt_searchers.bds:BDSSearcher", {"n_init": 1}),
    "bds n_init=5": ("jt_searchers.bds:BDSSearcher", {"n_init": 5}),
    "random": ("jt_searchers.random_search:RandomSearcher", {}),
    "random sobol": ("jt_searchers.random_search:RandomSearcher", {"method": "sobol"}),
}


def _load(path: str) -> type:
    mod, name = path.split(":")
    return getattr(__import__(mod, fromlist=[name]), name)


def _distinct_run(args: tuple) -> float:
    land, searcher, seed, n = args
    from jt_tasks.strategy_landscape import StrategyLandscapeTask

    task = StrategyLandscapeTask({"task": LANDSCAPES[land]})
    path, cfg = SEARCHERS[searcher]
    cfg = dict(cfg, budget=n)
    _, _, evals = run_search(_load(path), task, cfg, seed, batch=cfg.get("batch", 1))
    return task.summarize(evals, Path("."))["distinct_strategies"]


def distinct(seeds: int, n: int, jobs: int, landscapes: list[str], searchers: list[str]) -> None:
    from jt_tasks.strategy_landscape import StrategyLandscapeTask

    print(f"distinct strategies in the first {n} samples, mean ± std over seeds 0..{seeds - 1}\n")
    print("| landscape | E[random] | " + " | ".join(searchers) + " |")
    print("|---" * (len(searchers) + 2) + "|")
    with ProcessPoolExecutor(jobs) as pool:
        for land in landscapes:
            expected = StrategyLandscapeTask({"task": LANDSCAPES[land]}).expected_random_distinct(n)
            cells = []
            for s in searchers:
                v = np.array(list(pool.map(_distinct_run, [(land, s, seed, n) for seed in range(seeds)])))
                cells.append(f"{v.mean():.2f} ± {v.std():.2f}")
            print(f"| {land} | {expected:.2f} | " + " | ".join(cells) + " |", flush=True)


MO_SEARCHERS = {
    "rmoo": ("jt_searchers.rmoo:RMOOSearcher", {}),
    "rmoo (sigma0=0.1)": ("jt_searchers.rmoo:RMOOSearcher", {"sigma0": 0.1}),
    "bsoo": ("jt_searchers.bsoo:BSOOSearcher", {"bin_low": 0.0, "bin_high": 1.0}),
    "bsoo (range sampled)": ("jt_searchers.bsoo:BSOOSearcher", {}),
    "random": ("jt_searchers.random_search:RandomSearcher", {}),
}


def _zdt_run(args: tuple) -> float:
    searcher, seed, budget, n_var = args
    from jt_tasks.zdt import ZDT1Task

    task = ZDT1Task({"task": {"n_var": n_var}})
    path, cfg = MO_SEARCHERS[searcher]
    _, _, evals = run_search(_load(path), task, dict(cfg, budget=budget), seed, batch=16)
    return task.summarize(evals, Path("."))["hv_ratio"]


def zdt(seeds: int, budgets: list[int], n_var: int, jobs: int, searchers: list[str]) -> None:
    print(f"ZDT1 (n={n_var}) hypervolume / true front's, reference (11, 11), mean ± std over seeds 0..{seeds - 1}\n")
    print("| budget | " + " | ".join(searchers) + " |")
    print("|---" * (len(searchers) + 1) + "|")
    with ProcessPoolExecutor(jobs) as pool:
        for b in budgets:
            cells = []
            for s in searchers:
                v = np.array(list(pool.map(_zdt_run, [(s, seed, b, n_var) for seed in range(seeds)])))
                cells.append(f"{v.mean():.4f} ± {v.std():.4f}")
            print(f"| {b} | " + " | ".join(cells) + " |", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("bench", choices=["distinct", "zdt"])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--n", type=int, default=10, help="samples per run (distinct)")
    ap.add_argument("--budgets", type=int, nargs="+", default=[500, 1000, 2000, 5000])
    ap.add_argument("--n-var", type=int, default=30)
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--landscapes", nargs="+", default=list(LANDSCAPES))
    ap.add_argument("--searchers", nargs="+", default=None,
                    help=f"distinct: {list(SEARCHERS)}; zdt: {list(MO_SEARCHERS)}")
    a = ap.parse_args()
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    if a.bench == "distinct":
        distinct(a.seeds, a.n, a.jobs, a.landscapes, a.searchers or list(SEARCHERS))
    else:
        zdt(a.seeds, a.budgets, a.n_var, a.jobs, a.searchers or list(MO_SEARCHERS))


if __name__ == "__main__":
    main()
