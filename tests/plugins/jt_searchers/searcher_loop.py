"""A tiny ask → evaluate → tell loop for tests and benchmarks (the lead's runner does this for real)."""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any, Optional

import numpy as np

from toolkit.interfaces.task import EvalContext
from toolkit.testing.searcher import eval_seed  # the contract suite's seeds, one source


def run_search(
    searcher_cls: type,
    task: Any,
    cfg: Any,
    seed: int,
    batch: Optional[int] = None,
    workdir: Optional[Path] = None,
    max_steps: int = 100_000,
) -> tuple[Any, np.ndarray, list]:
    """Run a searcher on a task until ``finished()``.

    Returns:
        The searcher, the evaluated points ``(n, dim)`` and the evaluations, in order.
    """
    problem = task.problem()
    s = searcher_cls(problem, cfg, seed)
    batch = batch or int(getattr(s.cfg, "batch", 1))
    workdir = Path(workdir or tempfile.mkdtemp(prefix="jt_search_"))
    points, evals = [], []
    for _ in range(max_steps):
        if s.finished():
            break
        X = s.ask(batch)
        if len(X) == 0:
            break
        res = []
        for x in X:
            i = len(evals) + len(res)
            ctx = EvalContext(index=i, seed=eval_seed(seed, i), workdir=workdir)
            res.append(task.evaluate(problem.space.to_dict(x), ctx))
        s.tell(X, res)
        points.extend(X)
        evals.extend(res)
    return s, np.array(points).reshape(-1, problem.space.dim), evals
