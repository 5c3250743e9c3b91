"""``search=rmoo``: re-sampled multi-objective optimisation (``004`` §4.2–4.3, Algorithm 1).

mu parents, each a (1+1)-CMA-ES (``mo_cmaes``), start as copies of the input controller (the
box's default point) with its fitness. Every generation each parent mutates into one child; while
more than ``max_failed`` children failed, the failed ones are re-drawn from their parents (§4.3.1);
then parents and children (2 mu) are sorted by non-dominance rank and hypervolume contribution
(eq 16, ``pareto``) and the best mu become the next parents. A child is *successful* when it ranks
above its parent; both update their step size with that outcome, the child also its covariance
(Igel et al. 2007's steady (mu+mu) MO-CMA-ES). The search stops when no parent's objectives changed
by more than ``tol`` for ``patience`` generations (Alg. 1's "change of fitness < epsilon"), or at the budget.
"""

from __future__ import annotations

import dataclasses
from collections import deque
from typing import Any, Optional, Sequence

import numpy as np

from toolkit.errors import JtError

from jt_searchers.base import BudgetedSearcher, seed_int, check_budget
from jt_searchers.mo_cmaes import (
    Individual,
    StrategyParameters,
    objectives_of,
    step_of,
    update_covariance,
    update_step_size,
)
from jt_searchers.pareto import selection_order


SUCCESS_RULES = ("parent", "selected")  #: the two success definitions of ``Config.success``


class RMOOSearcher(BudgetedSearcher):
    """Re-sampled MO-CMA-ES: mu (1+1)-CMA-ES parents, hypervolume selection, failure resampling."""

    @dataclasses.dataclass
    class Config:

        def check(self) -> None:

            """budget and batch >= 1, mu >= 1, sigma0 > 0, a known success rule (one JtError line)."""
            from toolkit.schema import finite, require

            check_budget(self)
            require(self.mu >= 1, "search.mu", self.mu, "must be >= 1")
            require(finite(self.sigma0) and self.sigma0 > 0, "search.sigma0", self.sigma0, "must be a finite number > 0")
            require(self.max_failed >= 0 and self.max_resample_rounds >= 0 and self.patience >= 1,
                    "search.max_failed/max_resample_rounds/patience",
                    (self.max_failed, self.max_resample_rounds, self.patience), ">= 0, >= 0, >= 1")
            require(self.success in SUCCESS_RULES, "search.success", self.success, f"one of {', '.join(SUCCESS_RULES)}")

        budget: int = 2000
        """Total evaluations (004 runs to convergence; the budget bounds a run)."""
        batch: int = 16
        """One generation of mu children evaluated in parallel (004 §4.3.1, multi-threaded)."""
        mu: int = 16
        """Parents (004 §5: "RMOO with mu = 16")."""
        sigma0: float = 0.015
        """Initial step size in the box-normalised space (004 §4.1 gives it for BSOO; reused)."""
        max_failed: int = 3
        """At most 3 failed children per generation, the rest resampled (004 §4.3.1)."""
        max_resample_rounds: int = 20
        """Give up resampling a generation after this many rounds (ours)."""
        tol: float = 1e-9
        """Converged when no parent's fitness changes more than this (004 Alg. 1; value ours)."""
        patience: int = 10
        """... for this many generations in a row (ours)."""
        # selected child is common for an elitist ES, so a single one does not mean convergence)
        success: str = "parent"
        """A child succeeds when it ranks above its parent (Igel et al. 2007, followed by 004 §4.2.1); "selected": when selected into the next parents (Voss et al. 2010)."""
        # 2007, which 004 §4.2.1 follows); "selected": when it is selected into the next parents
        # (Voss, Hansen, Igel 2010, "Improved step size adaptation for the MO-CMA-ES")

    def __init__(self, problem: Any, cfg: Any, seed: int) -> None:
        super().__init__(problem, cfg, seed)
        if problem.n_objectives < 1:
            raise JtError("search=rmoo needs a task with objectives (problem() declares n_objectives >= 1), "
                          "e.g. task=standing_jump or task=zdt1")
        self.M = problem.n_objectives
        self.par = StrategyParameters.for_dim(self.box.dim)
        self.x0 = np.clip(self.box.to_unit(problem.space.defaults()), 0.0, 1.0)
        self.parents: list[Individual] = []
        self.children: list[Optional[Individual]] = []
        self.generation = 0
        self._round = 0  # resampling round within the generation
        self._queue: deque[tuple[str, int]] = deque([("init", 0)])  # what to hand out next
        self._asked: deque[tuple[str, int]] = deque()  # what was handed out, not yet told
        self._stall = 0
        # archive of every evaluation, for summary()
        self._U: list[np.ndarray] = []
        self._F: list[np.ndarray] = []
        self._failed: list[bool] = []
        self._gen: list[int] = []
        self.n_resampled = 0
        self._failed_at_selection: list[int] = []  # failed children left when each generation selected

    # ---- ask / tell plumbing --------------------------------------------------------------------------

    def _propose(self, k: int) -> np.ndarray:
        out = []
        while self._queue and len(out) < k:
            item = self._queue.popleft()
            self._asked.append(item)
            out.append(self.x0 if item[0] == "init" else self.children[item[1]].x)
        return np.array(out).reshape(-1, self.box.dim)

    def _observe(self, u: np.ndarray, results: Sequence[Any]) -> None:
        for row, r in zip(u, results):
            kind, k = self._asked.popleft()
            f, failed = objectives_of(r, self.M)
            self._U.append(row)
            self._F.append(f)
            self._failed.append(failed)
            self._gen.append(self.generation)
            index = len(self._U) - 1
            if kind == "init":
                ind = Individual.initial(self.x0, self.cfg.sigma0, self.par)
                ind.f, ind.failed, ind.index = f, failed, index
                self.parents = [ind.copy() for _ in range(self.cfg.mu)]  # 004 Alg. 1: copies of the input
            else:
                child = self.children[k]
                child.f, child.failed, child.index = f, failed, index
        if not self._queue and not self._asked and self.parents:
            self._round_complete()

    def _round_complete(self) -> None:
        """All children of this round are in: resample failures (§4.3.1) or select (eq 16)."""
        if self.children:
            bad = [k for k, c in enumerate(self.children) if c.failed]
            if len(bad) > self.cfg.max_failed and self._round < self.cfg.max_resample_rounds:
                self._round += 1
                for k in bad:  # copies of the unsuccessful children's parents, mutated anew
                    self.children[k] = self.parents[k].mutate(self._rng(k))
                    self._queue.append(("child", k))
                self.n_resampled += len(bad)
                return
            self._select()
        self._new_generation()

    def _rng(self, k: int) -> np.random.Generator:
        return np.random.default_rng(seed_int(self.seed, self.generation, k, self._round))

    def _new_generation(self) -> None:
        self.generation += 1
        self._round = 0
        self.children = [p.mutate(self._rng(k)) for k, p in enumerate(self.parents)]
        self._queue.extend(("child", k) for k in range(len(self.children)))

    # ---- selection (004 eq 16) and strategy updates (Igel et al. 2007) ----------------------------------

    def _select(self) -> None:
        mu = len(self.parents)
        Q = self.parents + self.children
        F = np.array([q.f for q in Q], dtype=float).reshape(len(Q), self.M)
        order = selection_order(F, np.array([q.failed for q in Q]))
        position = np.empty(len(Q), dtype=int)
        position[order] = np.arange(len(Q))
        before = np.array([p.f for p in self.parents], dtype=float)
        self._failed_at_selection.append(sum(c.failed for c in self.children))
        for k in range(mu):
            parent, child = self.parents[k], self.children[k]
            if self.cfg.success == "selected":
                success = float(position[mu + k] < mu)
            else:
                success = float(position[mu + k] < position[k])
            step = step_of(parent, child)
            update_step_size(parent, success, self.par)
            update_step_size(child, success, self.par)
            update_covariance(child, step, self.par)
        self.parents = [Q[i].copy() for i in order[:mu]]
        after = np.array([p.f for p in self.parents], dtype=float)
        change = _set_change(before, after)
        self._stall = self._stall + 1 if change < self.cfg.tol else 0

    def _converged(self) -> bool:
        return self._stall >= self.cfg.patience

    # ---- results ---------------------------------------------------------------------------------------

    def summary(self) -> dict[str, Any]:
        U = np.array(self._U).reshape(-1, self.box.dim)
        F = np.array(self._F).reshape(-1, self.M)
        return {
            "X": self.box.from_unit(U),
            "objectives": F,
            "failed": np.array(self._failed, dtype=bool),
            "generation": np.array(self._gen, dtype=int),
            "parents_X": self.box.from_unit(np.array([p.x for p in self.parents]).reshape(-1, self.box.dim)),
            "parents_objectives": np.array([p.f for p in self.parents], dtype=float).reshape(-1, self.M),
            "parents_sigma": np.array([p.sigma for p in self.parents], dtype=float),
            "parents_index": np.array([p.index for p in self.parents], dtype=int),
            "n_generations": np.int64(self.generation),
            "n_resampled": np.int64(self.n_resampled),
            "failed_at_selection": np.array(self._failed_at_selection, dtype=int),
        }


def _set_change(before: np.ndarray, after: np.ndarray) -> float:
    """Largest change between two populations' objective vectors ``(mu, M)``, compared as sorted sets."""
    if before.shape != after.shape:
        return np.inf
    b = before[np.lexsort(before.T[::-1])]
    a = after[np.lexsort(after.T[::-1])]
    if not np.array_equal(np.isnan(a), np.isnan(b)):
        return np.inf  # a failed parent was replaced (or the reverse)
    diff = np.abs(np.nan_to_num(a) - np.nan_to_num(b))  # failed (NaN) rows compare equal
    return float(diff.max()) if diff.size else 0.0
