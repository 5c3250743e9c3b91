"""(1+1)-CMA-ES individuals as MO-CMA-ES uses them (Igel, Hansen, Roth 2007; ``004`` §4.2.1).

Each individual carries its own search distribution: mean ``x``, global step size ``sigma``,
covariance ``C``, evolution path ``p_c`` and smoothed success rate ``p_succ``. Step size follows
the success rule, covariance the rank-one update with the evolution path (Igel et al. 2007,
procedures *updateStepSize* and *updateCovariance*, strategy parameters of their Table 1 with
``lambda = 1``):

    d = 1 + n / 2,  p_target = 1 / (5 + 1/2),  c_p = p_target / (2 + p_target),
    c_c = 2 / (n + 2),  c_cov = 2 / (n^2 + 6),  p_thresh = 0.44.

Points live in the unit cube; a mutation that leaves it is reflected back at the faces, and the
reflected step is the one the covariance update sees.
"""

from __future__ import annotations

import dataclasses
import numpy as np

from jt_searchers.base import reflect_unit


@dataclasses.dataclass(frozen=True)
class StrategyParameters:
    """Constants of the (1+1)-CMA-ES for dimension ``n`` (Igel et al. 2007, Table 1, ``lambda = 1``)."""

    n: int
    d: float
    p_target: float
    c_p: float
    c_c: float
    c_cov: float
    p_thresh: float = 0.44

    @classmethod
    def for_dim(cls, n: int) -> "StrategyParameters":
        p_target = 1.0 / (5.0 + 0.5)
        return cls(
            n=n,
            d=1.0 + n / 2.0,
            p_target=p_target,
            c_p=p_target / (2.0 + p_target),
            c_c=2.0 / (n + 2.0),
            c_cov=2.0 / (n * n + 6.0),
        )


@dataclasses.dataclass
class Individual:
    """One (1+1)-CMA-ES: a point, its objectives and its own search distribution.

    Attributes:
        x: point in the unit cube ``(n,)``.
        sigma: global step size.
        C: covariance ``(n, n)``.
        pc: evolution path ``(n,)``.
        p_succ: smoothed success probability.
        f: objectives ``(M,)`` (empty until evaluated).
        failed: the evaluation failed.
        index: evaluation number of ``x`` in the run (-1 if none).
    """

    x: np.ndarray
    sigma: float
    C: np.ndarray
    pc: np.ndarray
    p_succ: float
    f: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0))
    failed: bool = False
    index: int = -1

    @classmethod
    def initial(cls, x: np.ndarray, sigma: float, par: StrategyParameters) -> "Individual":
        n = len(x)
        return cls(x=np.array(x, float), sigma=float(sigma), C=np.eye(n), pc=np.zeros(n), p_succ=par.p_target)

    def copy(self) -> "Individual":
        return Individual(self.x.copy(), self.sigma, self.C.copy(), self.pc.copy(), self.p_succ,
                          self.f.copy(), self.failed, self.index)

    def mutate(self, rng: np.random.Generator) -> "Individual":
        """An offspring ``x' = reflect(x + sigma * A z)``, ``A A^T = C``, that inherits the strategy."""
        child = self.copy()
        A = np.linalg.cholesky(self.C + 1e-14 * np.eye(len(self.x)))
        child.x = reflect_unit(self.x + self.sigma * (A @ rng.standard_normal(len(self.x))))
        child.f, child.failed, child.index = np.zeros(0), False, -1
        return child


def update_step_size(ind: Individual, success: float, par: StrategyParameters) -> None:
    """Success rule: ``p_succ <- (1-c_p) p_succ + c_p * success``, then
    ``sigma *= exp((p_succ - p_target) / (d (1 - p_target)))``."""
    ind.p_succ = (1.0 - par.c_p) * ind.p_succ + par.c_p * float(success)
    ind.sigma *= float(np.exp((ind.p_succ - par.p_target) / (par.d * (1.0 - par.p_target))))


def update_covariance(ind: Individual, step: np.ndarray, par: StrategyParameters) -> None:
    """Rank-one covariance update with the evolution path; ``step = (x' - x) / sigma`` ``(n,)``.

    While the success rate is high (``p_succ >= p_thresh``) the path is not extended, which stops
    it growing too fast when the step size is small (Igel et al. 2007, *updateCovariance*).
    """
    if ind.p_succ < par.p_thresh:
        ind.pc = (1.0 - par.c_c) * ind.pc + np.sqrt(par.c_c * (2.0 - par.c_c)) * step
        ind.C = (1.0 - par.c_cov) * ind.C + par.c_cov * np.outer(ind.pc, ind.pc)
    else:
        ind.pc = (1.0 - par.c_c) * ind.pc
        rank_one = np.outer(ind.pc, ind.pc) + par.c_c * (2.0 - par.c_c) * ind.C
        ind.C = (1.0 - par.c_cov) * ind.C + par.c_cov * rank_one
    ind.C = 0.5 * (ind.C + ind.C.T)


def objectives_of(result: object, n_objectives: int) -> tuple[np.ndarray, bool]:
    """Objectives ``(M,)`` of an ``Evaluation`` and whether it counts as failed (flag, size, NaN)."""
    f = np.asarray(getattr(result, "objectives", ()), dtype=float).ravel()
    failed = bool(getattr(result, "failed", False)) or f.size != n_objectives or not np.all(np.isfinite(f))
    return (np.full(n_objectives, np.nan) if failed else f), failed


def step_of(parent: Individual, child: Individual) -> np.ndarray:
    """The normalised step ``(x_child - x_parent) / sigma_parent`` ``(n,)`` (after reflection)."""
    return (child.x - parent.x) / max(parent.sigma, 1e-300)


__all__ = [
    "Individual",
    "StrategyParameters",
    "objectives_of",
    "step_of",
    "update_covariance",
    "update_step_size",
]

