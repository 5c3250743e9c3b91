"""``task=zdt1``: the ZDT1 bi-objective test problem, with its known Pareto front (RMOO vs BSOO).

ZDT1 (Zitzler, Deb, Thiele 2000), ``n`` variables in ``[0, 1]``, both objectives minimised:

    f1 = x1,   g = 1 + 9 / (n - 1) * sum_{i>=2} x_i,   f2 = g * (1 - sqrt(f1 / g)).

The Pareto front is ``f2 = 1 - sqrt(f1)``, ``f1 in [0, 1]`` (all ``x_i = 0`` for ``i >= 2``). Its
hypervolume up to a reference point ``r`` has a closed form (``true_hypervolume``); with
``r = (11, 11)`` it is ``121 - 1/3``. ``(11, 11)`` is worse than every point of the box
(``f1 <= 1``, ``f2 <= g <= 10``), so every evaluation counts toward the hypervolume.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, ClassVar, Sequence

import numpy as np

from toolkit.interfaces.searcher import Param, SearchProblem, Space
from toolkit.interfaces.task import EvalContext, Evaluation, Task
from toolkit.config import task_params
from toolkit.errors import JtError


def zdt1(x: np.ndarray) -> np.ndarray:
    """ZDT1 objectives of points ``(..., n)`` → ``(..., 2)``."""
    x = np.asarray(x, dtype=float)
    f1 = x[..., 0]
    g = 1.0 + 9.0 * np.mean(x[..., 1:], axis=-1) if x.shape[-1] > 1 else np.ones_like(f1)
    f2 = g * (1.0 - np.sqrt(np.clip(f1 / g, 0.0, None)))
    return np.stack([f1, f2], axis=-1)


def true_hypervolume(ref: Sequence[float]) -> float:
    """Hypervolume of the ZDT1 Pareto front ``f2 = 1 - sqrt(f1)`` up to ``ref = (r1, r2)``, exactly.

    ``integral over f1 in [a, b] of (r2 - 1 + sqrt(f1))`` where the front lies below ``r2``
    (``a = max(0, 1 - r2)^2``, ``b = min(1, r1)``), plus the strip ``f1 in [1, r1]`` of height ``r2``.
    """
    r1, r2 = float(ref[0]), float(ref[1])
    a, b = max(0.0, 1.0 - r2) ** 2, min(1.0, r1)
    hv = (r2 - 1.0) * (b - a) + (2.0 / 3.0) * (b**1.5 - a**1.5) if b > a else 0.0
    return hv + max(0.0, r1 - 1.0) * max(0.0, r2)


def hypervolume(F: np.ndarray, ref: Sequence[float]) -> float:
    """Hypervolume (moocore) of points ``(n, 2)`` up to ``ref``; points beyond ``ref`` add nothing."""
    import moocore

    ref = np.asarray(ref, dtype=float)
    F = F[np.all(np.isfinite(F), axis=1) & np.all(F < ref, axis=1)]
    return float(moocore.hypervolume(F, ref=ref)) if len(F) else 0.0


class ZDT1Task(Task):
    """ZDT1 bi-objective benchmark with its exact front hypervolume."""

    ignores_groups: ClassVar[tuple[str, ...]] = ("action", "reward", "curriculum", "sim", "spd", "character", "agent")

    key_metrics: ClassVar[tuple[str, ...]] = ("hv_ratio", "hypervolume")

    @dataclasses.dataclass
    class Config:
        n_var: int = 30
        """ZDT1's standard number of variables."""
        reference_point: list[float] = dataclasses.field(default_factory=lambda: [11.0, 11.0])
        """Hypervolume reference: worse than any point of the box (f1 <= 1, f2 <= 10)."""
        # reference, worse than every point of the box

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        self.params = task_params(self.Config, cfg)
        if self.params.n_var < 2:
            raise JtError("zdt1 needs n_var >= 2")

    def problem(self) -> SearchProblem:
        return SearchProblem(
            space=Space(tuple(Param(f"x{i}", 0.0, 1.0) for i in range(self.params.n_var))),
            n_objectives=2,
            objective_names=("f1", "f2"),
            reference_point=list(self.params.reference_point),
        )

    def evaluate(self, point: dict[str, float], ctx: EvalContext) -> Evaluation:
        x = np.array([point[f"x{i}"] for i in range(self.params.n_var)], dtype=float)
        f = zdt1(x)
        return Evaluation(metrics={"f1": float(f[0]), "f2": float(f[1])}, objectives=[float(v) for v in f])

    def summarize(self, evaluations: Sequence[Evaluation], workdir: Path) -> dict[str, float]:
        ref = self.params.reference_point
        F = np.array([e.objectives for e in evaluations if not e.failed and len(e.objectives) == 2],
                     dtype=float)
        hv = hypervolume(F.reshape(-1, 2), ref)
        return {"hypervolume": hv, "hv_ratio": hv / true_hypervolume(ref),
                "n_evaluations": float(len(evaluations))}
