"""``search=bsoo``: binned single-objective optimisation (``004`` §4.1), the RMOO baseline.

Objective 1 (the task quantity, jump height in ``004``) is split into ``n_bins`` uniform bins; each
bin is one CMA-ES run (``cma`` package; ``popsize`` offspring, initial ``sigma0`` in the
box-normalised space) on ``004`` eq 5 with eqs 1–3:

    f_SO = C_H + C_L + f_2,   C_H = w_p (f_1 - h_o)^2 if |f_1 - h_o| > h_r else 0,   C_L = f_p on failure,

where ``h_o`` is the bin centre and ``h_r`` half its width (inside the bin costs nothing, outside
a quadratic penalty), ``f_p`` a failure penalty larger than any fitness. A bin stops when its best
``f_SO`` improved by less than ``eps`` over ``stall_generations`` generations, or after
``max_generations`` (§4.1), or on the CMA-ES's own convergence tests (``tolx``, ``tolfun``). The
first bin starts from the input controller (the box's default point); every next bin starts from
the previous bin's optimum (§4.1). Bins are swept outward from the bin holding the input
controller's objective 1 (the paper starts at the low jump it is given and moves up), then the
bins on the other side, from the first bin's optimum.

The run budget (not in the paper, which optimises every bin to convergence) is shared: a bin may
use at most the remaining budget divided by the remaining bins, so every bin gets optimised.
"""

from __future__ import annotations

import dataclasses
from collections import deque
from typing import Any, Optional, Sequence

import numpy as np

from toolkit.errors import JtError

from jt_searchers.base import BudgetedSearcher, seed_int, check_budget, unit_samples
from jt_searchers.mo_cmaes import objectives_of


def binned_objective(
    f: np.ndarray, failed: bool, centre: float, half_width: float, w_p: float, f_p: float
) -> float:
    """``004`` eq 5 for one bin: height-bracket penalty (eq 2) + failure penalty (eq 3) + objective 2."""
    if failed:
        return float(f_p)
    dev = float(f[0]) - centre
    c_h = w_p * dev * dev if abs(dev) > half_width else 0.0
    return c_h + float(f[1])


class BSOOSearcher(BudgetedSearcher):
    """Binned single-objective CMA-ES: one warm-started CMA-ES per bin of objective 1."""

    @dataclasses.dataclass
    class Config:

        def check(self) -> None:

            """budget and batch >= 1 (one JtError line)."""

            check_budget(self)

        budget: int = 2000
        """Total evaluations, shared evenly by the remaining bins (ours; 004 runs every bin to convergence)."""
        batch: int = 16
        """One CMA-ES generation per ask (004 §4.1: 16 offspring)."""
        n_bins: int = 16
        """Uniformly spaced bins of objective 1 (004 §4.1)."""
        popsize: int = 16
        """CMA-ES offspring per generation (004 §4.1)."""
        sigma0: float = 0.015
        """Initial CMA-ES step size, box-normalised space (004 §4.1)."""
        stall_generations: int = 300
        """Stop a bin after 300 generations with less than eps improvement (004 §4.1)."""
        max_generations: int = 3000
        """... or after 3000 generations (004 §4.1)."""
        eps: float = 1e-8
        """Improvement threshold epsilon (004 §4.1 gives no value; ours)."""
        w_p: float = 5000.0
        """Bin (height) penalty weight, eq 2 (004 §3.2)."""
        f_p: float = 100000.0
        """Failure penalty, eq 3 (004 §3.2)."""
        bin_low: Optional[float] = None
        """Objective-1 range split into bins; null = min/max over a random sample (ours)."""
        bin_high: Optional[float] = None
        """(upper end; see bin_low)."""
        range_samples: int = 15
        """Size of that random sample, used only when bin_low/bin_high are null (ours)."""

    def __init__(self, problem: Any, cfg: Any, seed: int) -> None:
        super().__init__(problem, cfg, seed)
        if problem.n_objectives != 2:
            raise JtError("search=bsoo needs a task with exactly two objectives (the binned task quantity and "
                          "the cost), e.g. task=standing_jump")
        c = self.cfg
        self.x0 = np.clip(self.box.to_unit(problem.space.defaults()), 0.0, 1.0)
        need_range = c.bin_low is None or c.bin_high is None
        n_range = c.range_samples if need_range else 0
        self._init_points = np.vstack([self.x0[None], unit_samples(n_range, self.box.dim, seed_int(seed, 9))])
        self._queue: deque[tuple[int, int]] = deque((-1, j) for j in range(len(self._init_points)))
        self._asked: deque[tuple[int, int]] = deque()
        self._init_results: list[tuple[np.ndarray, bool]] = []
        self.edges: Optional[np.ndarray] = None
        self.order: list[int] = []  # bins in the order they are optimised
        self._start_from: dict[int, int] = {}  # bin -> bin whose optimum seeds it (-1: the input controller)
        self.best: dict[int, dict[str, Any]] = {}  # bin -> best point found for it
        self._es: Any = None
        self._bin_pos = -1
        self._done = False
        self._U: list[np.ndarray] = []
        self._F: list[np.ndarray] = []
        self._failed: list[bool] = []
        self._bin_of_eval: list[int] = []

    # ---- set-up ---------------------------------------------------------------------------------------

    def _plan(self) -> None:
        """Bin edges from the config or the initial sample; sweep order from the input controller's bin."""
        c = self.cfg
        f0, failed0 = self._init_results[0]
        lo, hi = c.bin_low, c.bin_high
        if lo is None or hi is None:
            ok = np.array([f[0] for f, bad in self._init_results if not bad])
            lo = float(ok.min()) if lo is None and len(ok) else (lo if lo is not None else 0.0)
            hi = float(ok.max()) if hi is None and len(ok) else (hi if hi is not None else 1.0)
        if not hi > lo:
            hi = lo + 1.0
        self.edges = np.linspace(lo, hi, c.n_bins + 1)
        # bins are half-open [low, high): the input controller's objective 1 picks the first bin
        b0 = 0 if failed0 else int(np.clip(np.searchsorted(self.edges, f0[0], side="right") - 1,
                                           0, c.n_bins - 1))
        self.order = list(range(b0, c.n_bins)) + list(range(b0 - 1, -1, -1))
        self._start_from = {b0: -1}
        self._start_from.update({b: b - 1 for b in range(b0 + 1, c.n_bins)})
        self._start_from.update({b: b + 1 for b in range(b0 - 1, -1, -1)})

    def _start_bin(self) -> None:
        import cma

        c = self.cfg
        self._bin_pos += 1
        if self._bin_pos >= len(self.order):
            self._done = True
            return
        b = self.order[self._bin_pos]
        src = self._start_from[b]
        x_start = self.x0 if src < 0 or src not in self.best else self.best[src]["u"]
        rng = np.random.default_rng(seed_int(self.seed, 100, b))
        self._es = cma.CMAEvolutionStrategy(
            np.array(x_start, dtype=float),
            c.sigma0,
            {
                "bounds": [0.0, 1.0],
                "popsize": c.popsize,
                "seed": np.nan,  # no global numpy seeding: our generator draws the samples
                "randn": lambda *shape: rng.standard_normal(shape),
                "maxiter": c.max_generations,
                "tolstagnation": c.max_generations + 1,  # the paper's stall test replaces these two
                "tolflatfitness": c.max_generations + 1,
                "verbose": -9,
                "verb_disp": 0,
                "verb_log": 0,
            },
        )
        self._gen = 0
        self._history: list[float] = []  # best f_SO so far, per generation
        self._bin_evals = 0
        remaining_bins = len(self.order) - self._bin_pos
        self._bin_cap = max(c.popsize, (self.budget - self.n_asked) // remaining_bins)
        self.best[b] = {"u": np.array(x_start, float), "f": np.full(2, np.nan), "f_so": np.inf,
                        "evals": 0, "gens": 0}
        self._ask_generation()

    def _ask_generation(self) -> None:
        self._solutions = [np.asarray(x, dtype=float) for x in self._es.ask()]
        self._fso = [np.nan] * len(self._solutions)
        self._queue.extend((self.order[self._bin_pos], j) for j in range(len(self._solutions)))

    # ---- ask / tell -----------------------------------------------------------------------------------

    def _propose(self, k: int) -> np.ndarray:
        out = []
        while self._queue and len(out) < k:
            b, j = self._queue.popleft()
            self._asked.append((b, j))
            out.append(self._init_points[j] if b < 0 else self._solutions[j])
        return np.array(out).reshape(-1, self.box.dim)

    def _observe(self, u: np.ndarray, results: Sequence[Any]) -> None:
        for row, r in zip(u, results):
            b, j = self._asked.popleft()
            f, failed = objectives_of(r, 2)
            self._U.append(row)
            self._F.append(f)
            self._failed.append(failed)
            self._bin_of_eval.append(b)
            if b < 0:
                self._init_results.append((f, failed))
            else:
                width = self.edges[1] - self.edges[0]
                centre = 0.5 * (self.edges[b] + self.edges[b + 1])
                self._fso[j] = binned_objective(f, failed, centre, 0.5 * width, self.cfg.w_p, self.cfg.f_p)
                self._bin_evals += 1
                if self._fso[j] < self.best[b]["f_so"]:
                    self.best[b].update(u=row.copy(), f=f.copy(), f_so=self._fso[j])
        if self._queue or self._asked:
            return
        if self.edges is None:
            self._plan()
            self._start_bin()
        else:
            self._end_generation()

    def _end_generation(self) -> None:
        c = self.cfg
        b = self.order[self._bin_pos]
        self._es.tell(self._solutions, [float(v) for v in self._fso])
        self._gen += 1
        self._history.append(self.best[b]["f_so"])
        self.best[b].update(evals=self._bin_evals, gens=self._gen)
        h = self._history
        stalled = len(h) > c.stall_generations and h[-1 - c.stall_generations] - h[-1] < c.eps
        over_cap = self._bin_evals + c.popsize > self._bin_cap
        if stalled or self._gen >= c.max_generations or over_cap or self._es.stop():
            self._start_bin()
        else:
            self._ask_generation()

    def _converged(self) -> bool:
        return self._done

    def summary(self) -> dict[str, Any]:
        U = np.array(self._U).reshape(-1, self.box.dim)
        bins = sorted(self.best)
        out = {
            "X": self.box.from_unit(U),
            "objectives": np.array(self._F, dtype=float).reshape(-1, 2),
            "failed": np.array(self._failed, dtype=bool),
            "bin_of_eval": np.array(self._bin_of_eval, dtype=int),
            "bin_edges": np.asarray(self.edges if self.edges is not None else [], dtype=float),
            "bin_order": np.array(self.order, dtype=int),
            "bins": np.array(bins, dtype=int),
            "bin_best_X": self.box.from_unit(
                np.array([self.best[b]["u"] for b in bins]).reshape(-1, self.box.dim)
            ),
            "bin_best_objectives": np.array([self.best[b]["f"] for b in bins], dtype=float).reshape(-1, 2),
            "bin_best_fso": np.array([self.best[b]["f_so"] for b in bins], dtype=float),
            "bin_generations": np.array([self.best[b]["gens"] for b in bins], dtype=int),
        }
        return out
