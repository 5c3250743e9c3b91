"""``task=strategy_landscape``: a synthetic strategy-discovery benchmark for BDS (``000`` §7.2.1).

The ``dims``-dimensional box is partitioned into ``n_strategies`` hidden "strategies": the cells of
a seeded power diagram (a Voronoi diagram whose sites carry weights), so a few cells are large flat
regions and many are small — ``000`` §7.2.1 attributes random search's poor showing to exactly such
"large flat regions in the strategy space where different initial states lead to the same
strategy". Every point of a cell returns the cell's plateau feature vector plus Gaussian noise.
Plateau values are a smooth function of the cell site (neighbouring strategies look alike, as
neighbouring take-off states do), and are at least ``min_separation`` apart, so clustering the
features with ``distinct_threshold`` recovers the cells. Optionally the ``n_failing`` smallest cells
are failures (falls): no features.

``summarize`` counts distinct strategies (cells hit) in the first n evaluations, the number the
paper compares: BDS found 6 in its first 10 samples, random search 3 (``000`` §7.1.1, §7.2.1).
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


class StrategyLandscapeTask(Task):
    """Synthetic box of hidden strategy cells (unequal sizes) with plateau features + noise."""

    ignores_groups: ClassVar[tuple[str, ...]] = ("action", "reward", "curriculum", "sim", "spd", "character", "agent")

    key_metrics: ClassVar[tuple[str, ...]] = ("distinct_at_10", "distinct_strategies")

    @dataclasses.dataclass
    class Config:
        dims: int = 4
        """Exploration-space dimension (000 §8: "a four dimensional space")."""
        n_strategies: int = 12
        """Hidden strategy cells (plateaus)."""
        n_features: int = 2
        """Feature dimension."""
        layout: str = "quantised"
        """"quantised": nearest plateau to a smooth latent field; "voronoi": random cells."""
        latent_scale: float = 0.12
        """Quantised: std of the latent field (smaller = more unequal cells); voronoi: weight spread."""
        # voronoi: spread of the power-diagram weights
        wiggle: float = 0.05
        """Quantised: amplitude of the latent field's nonlinear part."""
        noise: float = 0.02
        """Std of the noise on the plateau features (000 §5.1: g is stochastic)."""
        min_separation: float = 0.2
        """Least distance between two plateau feature vectors."""
        distinct_threshold: float = 0.1
        """Features closer than this count as one strategy."""
        n_failing: int = 0
        """The smallest cells fail (falls; 000 §7.1.1 counts "repetitions or failures")."""
        landscape_seed: int = 0
        """Seed of the landscape itself (the run seed drives only the noise); conf/task/strategy_landscape.yaml selects 1, the landscape docs/searchers.md documents."""
        low: float = -1.0
        """Lower bound of every parameter."""
        high: float = 1.0
        """Upper bound of every parameter."""

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        self.params = task_params(self.Config, cfg)
        self._build()

    # ---- the landscape ----------------------------------------------------------------------------

    def _build(self) -> None:
        p = self.params
        rng = np.random.default_rng(p.landscape_seed)
        # plateau features: n_strategies points of [0.05, 0.95]^m at least min_separation apart
        # (dart throwing: each new point is redrawn until it is far enough from the earlier ones)
        plateaus = np.zeros((0, p.n_features))
        for _ in range(p.n_strategies):
            for _ in range(10000):
                cand = 0.05 + 0.9 * rng.random(p.n_features)
                if np.all(np.linalg.norm(plateaus - cand, axis=1) >= p.min_separation):
                    break
            else:
                raise JtError("cannot separate the plateaus: lower min_separation or n_strategies")
            plateaus = np.vstack([plateaus, cand])
        self.plateaus = plateaus
        if p.layout == "quantised":
            # smooth latent feature field phi(u) = 0.5 + (u - 0.5) A + wiggle, quantised to the
            # nearest plateau: frequent strategies sit near the middle of phi's range, rare ones in
            # its tails (reached only from small regions of the box).
            a = rng.normal(size=(p.dims, p.n_features))
            self._A = a / np.linalg.norm(a, axis=0, keepdims=True) * p.latent_scale * np.sqrt(12.0)
            self._B = rng.normal(size=(p.dims, p.n_features)) * 2.0
            self._phase = 2 * np.pi * rng.random(p.n_features)
        elif p.layout == "voronoi":
            # power diagram of random sites with random weights; plateaus unrelated to position
            self.sites = rng.random((p.n_strategies, p.dims))
            self.weights = p.latent_scale * rng.random(p.n_strategies) ** 2
        else:
            raise JtError(f"unknown layout {p.layout!r} (use 'quantised' or 'voronoi')")
        self._volumes: np.ndarray | None = None
        self.failing: set[int] = set()
        if p.n_failing:
            self.failing = set(np.argsort(self.volumes(), kind="stable")[: p.n_failing].tolist())

    def latent(self, u: np.ndarray) -> np.ndarray:
        """Latent feature field of the quantised layout at unit points ``(n, dims)`` → ``(n, m)``."""
        u = np.atleast_2d(u) - 0.5
        return 0.5 + u @ self._A + self.params.wiggle * np.sin(u @ self._B * np.pi + self._phase)

    def cell(self, u: np.ndarray) -> np.ndarray:
        """Strategy index of unit-cube points ``(n, dims)`` → ``(n,)``."""
        u = np.atleast_2d(u)
        if self.params.layout == "quantised":
            d2 = np.sum((self.latent(u)[:, None, :] - self.plateaus[None]) ** 2, axis=-1)
        else:
            d2 = np.sum((u[:, None, :] - self.sites[None]) ** 2, axis=-1) - self.weights[None]
        return np.argmin(d2, axis=1)

    def volumes(self, n: int = 200_000) -> np.ndarray:
        """Fraction of the box each strategy occupies ``(K,)``, by seeded Monte-Carlo (cached)."""
        if self._volumes is None or self._volumes_n != n:
            u = np.random.default_rng(12345).random((n, self.params.dims))
            K = self.params.n_strategies
            counts = sum(np.bincount(self.cell(c), minlength=K) for c in np.array_split(u, 20))
            self._volumes, self._volumes_n = counts / n, n
        return self._volumes

    def expected_random_distinct(self, n: int) -> float:
        """Expected distinct (non-failing) strategies among ``n`` uniform samples: ``sum_k 1-(1-p_k)^n``."""
        vol = self.volumes()
        keep = [k for k in range(self.params.n_strategies) if k not in self.failing]
        return float(np.sum(1.0 - (1.0 - vol[keep]) ** n))

    # ---- the Task interface --------------------------------------------------------------------------

    def problem(self) -> SearchProblem:
        p = self.params
        return SearchProblem(
            space=Space(tuple(Param(f"x{i}", p.low, p.high) for i in range(p.dims))),
            n_features=p.n_features,
            feature_low=[0.0] * p.n_features,
            feature_high=[1.0] * p.n_features,
            distinct_threshold=p.distinct_threshold,
        )

    def evaluate(self, point: dict[str, float], ctx: EvalContext) -> Evaluation:
        p = self.params
        x = np.array([point[f"x{i}"] for i in range(p.dims)], dtype=float)
        u = (x - p.low) / (p.high - p.low)
        k = int(self.cell(u)[0])
        metrics = {"strategy": float(k)}
        if k in self.failing:
            return Evaluation(metrics=metrics, failed=True, reason=f"strategy {k} fails")
        f = self.plateaus[k] + p.noise * np.random.default_rng(ctx.seed).normal(size=p.n_features)
        return Evaluation(metrics=metrics, features=[float(v) for v in f])  # the runner logs features

    def summarize(self, evaluations: Sequence[Evaluation], workdir: Path) -> dict[str, float]:
        ok = [e for e in evaluations if not e.failed]
        found = [int(e.metrics["strategy"]) for e in ok]
        first10 = [int(e.metrics["strategy"]) for e in list(evaluations)[:10] if not e.failed]
        return {
            "distinct_strategies": float(len(set(found))),
            "distinct_at_10": float(len(set(first10))),
            "distinct_by_features": float(
                count_distinct([e.features for e in ok], self.params.distinct_threshold)
            ),
            "n_failed": float(len(evaluations) - len(ok)),
        }


def count_distinct(features: Sequence[Sequence[float]], threshold: float) -> int:
    """Strategies among feature vectors by leader clustering: a vector farther than ``threshold``
    from every earlier leader starts a new strategy (Euclidean)."""
    leaders: list[np.ndarray] = []
    for f in features:
        f = np.asarray(f, dtype=float)
        if all(np.linalg.norm(f - g) >= threshold for g in leaders):
            leaders.append(f)
    return len(leaders)
