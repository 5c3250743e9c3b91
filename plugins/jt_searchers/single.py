"""``search=single``: evaluate one point (a task run directly), in the outer run itself."""

from __future__ import annotations

from jt_searchers.base import check_budget

import dataclasses
from typing import Any, Sequence

import numpy as np

from toolkit.errors import JtError
from toolkit.interfaces import Evaluation, SearchProblem, Searcher


class SingleSearcher(Searcher):
    """Evaluate one given point (defaults of the task's box unless set)."""

    #: the evaluation is logged on the outer run (no nested child run)
    nested = False
    #: the one point is the user's (or the task's default): a constraint of the box does not apply
    honours_constraint = True

    @dataclasses.dataclass
    class Config:

        def check(self) -> None:

            """budget and batch >= 1 (one JtError line)."""

            check_budget(self)

        name: str = "single"
        budget: int = 1
        """Always one evaluation."""
        batch: int = 1
        """Always one point."""
        point: dict[str, float] = dataclasses.field(default_factory=dict)
        """Values for some of the task's parameters (``+search.point.alpha=0.3``); the rest
        take the task's defaults."""

    def __init__(self, problem: SearchProblem, cfg: Any, seed: int) -> None:
        super().__init__(problem, cfg, seed)
        given = dict(cfg.point) if cfg is not None and cfg.get("point") else {}
        unknown = sorted(set(given) - set(problem.space.names))
        if unknown:
            raise JtError(f"search.point: unknown parameter(s) {', '.join(unknown)}; "
                          f"the task's are: {', '.join(problem.space.names) or '(none)'}")
        x = problem.space.defaults()
        for i, p in enumerate(problem.space.params):
            if p.name in given:
                v = float(given[p.name])
                if not p.low <= v <= p.high:
                    raise JtError(f"search.point.{p.name}={v} is outside [{p.low}, {p.high}]")
                x[i] = v
        self._x = np.asarray(x, dtype=float)
        self._done = False

    def ask(self, n: int) -> np.ndarray:
        if self._done:
            return np.zeros((0, self.problem.space.dim))
        return self._x[None, :].copy()

    def tell(self, points: np.ndarray, results: Sequence[Evaluation]) -> None:
        self._done = True

    def finished(self) -> bool:
        return self._done
