"""What every built-in searcher shares: config parsing, the unit box, budget and FIFO bookkeeping."""

from __future__ import annotations

from collections import deque
from typing import Any, Sequence

import numpy as np

from toolkit.interfaces.searcher import SearchProblem, Searcher
from toolkit.config import config_of
from toolkit.errors import JtError


def seed_int(*entropy: int) -> int:
    """A 32-bit seed derived deterministically from integers (e.g. run seed, step)."""
    return int(np.random.SeedSequence([int(e) & 0xFFFFFFFF for e in entropy]).generate_state(1)[0])


_CONTROLLER: list[Any] = []  # one ThreadpoolController, built on first use (building one scans libraries)


def single_threaded_blas() -> Any:
    """Context limiting BLAS/OpenMP to one thread (``threadpoolctl``, a scikit-learn dependency).

    Searchers work on tiny matrices (a 30x30 eigendecomposition, a GP on tens of points), where
    multi-threaded BLAS only adds overhead: measured 3-10x slower on a 2-core machine.
    """
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:  # pragma: no cover - threadpoolctl ships with scikit-learn
        import contextlib

        return contextlib.nullcontext()
    if not _CONTROLLER:
        import scipy.linalg  # noqa: F401  (scipy ships its own BLAS: load it before scanning)

        _CONTROLLER.append(ThreadpoolController())
    return _CONTROLLER[0].limit(limits=1)


class UnitBox:
    """Affine map between the problem's box and the unit cube ``[0, 1]^dim``.

    Args:
        problem: the search problem whose ``space`` defines the box.
    """

    def __init__(self, problem: SearchProblem) -> None:
        self.low = np.asarray(problem.space.lows, dtype=float)
        self.high = np.asarray(problem.space.highs, dtype=float)
        self.dim = len(self.low)
        if np.any(self.high < self.low):
            raise JtError("every parameter needs low <= high")
        self.span = np.where(self.high > self.low, self.high - self.low, 1.0)

    def to_unit(self, x: np.ndarray) -> np.ndarray:
        """Box points ``(..., dim)`` → unit-cube points ``(..., dim)``."""
        return (np.asarray(x, dtype=float) - self.low) / self.span

    def from_unit(self, u: np.ndarray) -> np.ndarray:
        """Unit-cube points ``(..., dim)`` → box points ``(..., dim)``, clipped into the box."""
        x = self.low + np.clip(np.asarray(u, dtype=float), 0.0, 1.0) * self.span
        return np.clip(x, self.low, self.high)


def reflect_unit(u: np.ndarray) -> np.ndarray:
    """Reflect points ``(..., dim)`` into ``[0, 1]`` at the faces (period-2 mirror, any distance)."""
    v = np.mod(np.asarray(u, dtype=float), 2.0)
    return np.where(v > 1.0, 2.0 - v, v)


def check_budget(cfg: Any) -> None:
    """A searcher config's ``budget`` and ``batch`` are whole numbers >= 1 (one ``JtError`` line)."""
    for key in ("budget", "batch"):
        value = getattr(cfg, key, 1)
        if not isinstance(value, int) or value < 1:
            raise JtError(f"search.{key}={value}: must be a whole number >= 1")


def feasible_mask(problem: SearchProblem, box: UnitBox, u: np.ndarray) -> np.ndarray:
    """Whether unit points satisfy ``problem.constraint`` (all True without one).

    Args:
        problem: the search problem.
        box: the unit-cube map of its space.
        u: unit points ``(n, dim)``.

    Returns:
        ``(n,)`` bools.
    """
    u = np.atleast_2d(np.asarray(u, dtype=float)).reshape(-1, box.dim)
    if problem.constraint is None:
        return np.ones(len(u), dtype=bool)
    margins = np.asarray(problem.constraint(box.from_unit(u)), dtype=float).reshape(len(u))
    return margins >= 0.0


def unit_samples(n: int, dim: int, seed: int, method: str = "uniform") -> np.ndarray:
    """``n`` points of the unit cube ``(n, dim)``, a deterministic function of the arguments.

    Args:
        n: number of points.
        dim: dimension.
        seed: seed of the generator (or of the Sobol scrambling).
        method: ``"uniform"`` (i.i.d.) or ``"sobol"`` (scrambled Sobol', ``scipy.stats.qmc``).
    """
    if method == "uniform":
        return np.random.default_rng(seed).random((n, dim))
    if method == "sobol":
        from scipy.stats import qmc

        if n == 0 or dim == 0:
            return np.zeros((n, dim))
        try:
            sampler = qmc.Sobol(d=dim, scramble=True, rng=np.random.default_rng(seed))
        except TypeError:  # scipy < 1.15 names the argument ``seed``
            sampler = qmc.Sobol(d=dim, scramble=True, seed=np.random.default_rng(seed))
        m = int(np.ceil(np.log2(max(n, 1))))
        return sampler.random_base2(m)[:n]  # a power of two keeps the balance properties
    raise ValueError(f"unknown sampling method {method!r} (use 'uniform' or 'sobol')")


def feasible_samples(problem: SearchProblem, box: UnitBox, n: int, seed: int, method: str = "uniform") -> np.ndarray:
    """``n`` seeded unit points within ``problem.constraint``.

    Without a constraint exactly ``unit_samples(n, dim, seed, method)``. With one, the first ``n``
    feasible points of that design continued (rejection sampling: later rounds draw ``64 n`` more
    points from seeds derived from ``seed``), so the points are a deterministic function of the
    arguments.

    Args:
        problem: the search problem.
        box: the unit-cube map of its space.
        n: number of points.
        seed: seed of the design.
        method: ``"uniform"`` or ``"sobol"`` (``unit_samples``).

    Returns:
        Unit points ``(n, dim)``.

    Raises:
        JtError: fewer than ``n`` feasible points in ``n + 20 x 64 n`` draws.
    """
    u = unit_samples(n, box.dim, seed, method)
    if problem.constraint is None or n == 0:
        return u
    kept = u[feasible_mask(problem, box, u)]
    for k in range(1, 21):
        if len(kept) >= n:
            break
        more = unit_samples(64 * n, box.dim, seed_int(seed, 7919, k), method)
        kept = np.vstack([kept, more[feasible_mask(problem, box, more)]])
    if len(kept) < n:
        raise JtError(f"{problem.constraint_name or 'the task constraint'} leaves (almost) no point of the search box: "
                      "widen the box (task.ranges) or relax the constraint")
    return kept[:n]


class BudgetedSearcher(Searcher):
    """A searcher with a total evaluation budget and FIFO matching of told to asked points.

    Subclasses implement ``_propose(k)`` (up to ``k`` new points, unit cube ``(k', dim)``) and
    ``_observe(u, results)`` (results for points in the order they were proposed); this class
    handles the budget, the box map and the check that ``tell`` gets the points ``ask`` gave.

    Attributes:
        box: the unit-cube map.
        n_asked: points handed out so far.
        n_told: results received so far.
    """

    def __init__(self, problem: SearchProblem, cfg: Any, seed: int) -> None:
        super().__init__(problem, config_of(self.Config, cfg, f"search={type(self).name or type(self).__name__}"), seed)
        self.box = UnitBox(problem)
        self.n_asked = 0
        self.n_told = 0
        self._pending: deque[np.ndarray] = deque()  # unit points asked, not yet told

    @property
    def budget(self) -> int:
        return int(self.cfg.budget)

    def remaining(self) -> int:
        """Evaluations left to hand out."""
        return max(0, self.budget - self.n_asked)

    def ask(self, n: int) -> np.ndarray:
        k = min(int(n), self.remaining())
        if k <= 0 or self._converged():
            return np.zeros((0, self.box.dim))
        with single_threaded_blas():
            u = np.atleast_2d(np.asarray(self._propose(k), dtype=float)).reshape(-1, self.box.dim)[:k]
        for row in u:
            self._pending.append(row.copy())
        self.n_asked += len(u)
        return self.box.from_unit(u)

    def tell(self, points: np.ndarray, results: Sequence[Any]) -> None:
        points = np.atleast_2d(np.asarray(points, dtype=float))
        if len(points) != len(results):
            raise ValueError(f"tell: {len(points)} points but {len(results)} results")
        if len(points) > len(self._pending):
            raise ValueError("tell: more points than were asked")
        us = np.array([self._pending.popleft() for _ in range(len(points))]).reshape(-1, self.box.dim)
        if not np.allclose(self.box.from_unit(us), points, rtol=1e-9, atol=1e-9):
            raise ValueError("tell: points differ from the ones asked (tell them in ask order)")
        self.n_told += len(points)
        with single_threaded_blas():
            self._observe(us, list(results))

    def finished(self) -> bool:
        return self.n_told >= self.budget or (not self._pending and self._converged())

    def _converged(self) -> bool:
        """True when the algorithm has stopped on its own criteria (budget aside)."""
        return False

    def _propose(self, k: int) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def _observe(self, u: np.ndarray, results: list) -> None:  # pragma: no cover - abstract
        raise NotImplementedError
