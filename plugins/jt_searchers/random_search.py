"""``search=random``: seeded uniform or scrambled-Sobol samples of the box.

The baseline BDS is compared with (``000`` §7.2.1), and the initial design of BDS.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Sequence

import numpy as np

from jt_searchers.base import BudgetedSearcher, check_budget, feasible_samples


class RandomSearcher(BudgetedSearcher):
    """Uniform (or scrambled-Sobol) random samples of the box, seeded; within the problem's
    constraint when it has one (rejection sampling, ``base.feasible_samples``)."""

    honours_constraint = True

    @dataclasses.dataclass
    class Config:

        def check(self) -> None:

            """budget and batch >= 1, a known method (one JtError line)."""
            from toolkit.schema import require

            check_budget(self)
            require(self.method in ("uniform", "sobol"), "search.method", self.method, "uniform or sobol")

        budget: int = 10
        """Total evaluations; 000 §7.2.1 compares the first ten samples."""
        batch: int = 1
        """Points per ask (evaluated in parallel by the runner)."""
        method: str = "uniform"
        """"uniform" (i.i.d.) or "sobol" (scrambled Sobol', scipy.stats.qmc)."""

    def __init__(self, problem: Any, cfg: Any, seed: int) -> None:
        super().__init__(problem, cfg, seed)
        # The whole design is drawn up front, so the points never depend on how asks are batched.
        self._design = feasible_samples(problem, self.box, self.budget, seed, self.cfg.method)

    def _propose(self, k: int) -> np.ndarray:
        return self._design[self.n_asked : self.n_asked + k]

    def _observe(self, u: np.ndarray, results: Sequence[Any]) -> None:
        pass

    def summary(self) -> dict[str, Any]:
        return {"design": self.box.from_unit(self._design[: self.n_asked])}
