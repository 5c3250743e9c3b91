"""``search=random``: the contract, Sobol balance, and the analytic expectation on the landscape."""

from __future__ import annotations

import numpy as np

from jt_searchers.base import unit_samples
from jt_searchers.random_search import RandomSearcher
from jt_tasks.strategy_landscape import StrategyLandscapeTask
from toolkit.testing.searcher import SearcherContract, run_batches


class TestRandomUniform(SearcherContract):
    searcher_cls = RandomSearcher
    cfg = {"budget": 10, "batch": 3, "method": "uniform"}
    batch = 3
    golden_name = "random_uniform"

    def make_task(self) -> StrategyLandscapeTask:
        return StrategyLandscapeTask({"task": {}})


class TestRandomSobol(TestRandomUniform):
    cfg = {"budget": 10, "batch": 3, "method": "sobol"}
    golden_name = "random_sobol"


def test_points_do_not_depend_on_batching() -> None:
    task = StrategyLandscapeTask({"task": {}})
    a = RandomSearcher(task.problem(), {"budget": 9}, 5)
    b = RandomSearcher(task.problem(), {"budget": 9}, 5)
    xa = np.vstack([X for X, _ in run_batches(a, task, 1, 5)])
    xb = np.vstack([X for X, _ in run_batches(b, task, 4, 5)])
    np.testing.assert_array_equal(xa, xb)


def test_sobol_is_balanced() -> None:
    """Scrambled Sobol' with 2^m points puts exactly half the points in each half of every axis."""
    u = unit_samples(64, 4, seed=0, method="sobol")
    assert u.shape == (64, 4)
    np.testing.assert_array_equal(np.sum(u < 0.5, axis=0), [32] * 4)
    v = unit_samples(64, 4, seed=0, method="uniform")
    assert np.any(np.sum(v < 0.5, axis=0) != 32)  # i.i.d. points are not balanced


def test_distinct_strategies_match_the_analytic_expectation() -> None:
    """Random search's mean distinct-strategy count = sum_k 1 - (1 - p_k)^10 (cell volumes p_k)."""
    task = StrategyLandscapeTask({"task": {"noise": 0.0}})
    counts = []
    for seed in range(300):
        s = RandomSearcher(task.problem(), {"budget": 10}, seed)
        evs = [e for _, batch in run_batches(s, task, 10, seed) for e in batch]
        counts.append(task.summarize(evs, None)["distinct_at_10"])
    expected = task.expected_random_distinct(10)
    se = np.std(counts) / np.sqrt(len(counts))
    assert abs(np.mean(counts) - expected) < 4 * se + 0.02, (np.mean(counts), expected)
