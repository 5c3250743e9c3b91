"""``search=bsoo`` (004 §4.1): the contract, eq 5's bin penalty, the sweep, warm starts, stopping."""

from __future__ import annotations

import numpy as np
import pytest

from toolkit.errors import JtError

from jt_searchers.bsoo import BSOOSearcher, binned_objective
from jt_tasks.zdt import ZDT1Task
from toolkit.testing.searcher import SearcherContract, run_batches


class TestBSOO(SearcherContract):
    searcher_cls = BSOOSearcher
    cfg = {"budget": 81, "batch": 8, "n_bins": 4, "popsize": 8, "bin_low": 0.0, "bin_high": 1.0}
    batch = 8
    golden_name = "bsoo"
    golden_points = 9

    def make_task(self) -> ZDT1Task:
        return ZDT1Task({"task": {"n_var": 5}})


class TestBSOOSampledRange(TestBSOO):
    cfg = {"budget": 60, "batch": 8, "n_bins": 3, "popsize": 8, "range_samples": 7}
    golden_name = "bsoo_sampled_range"


def test_binned_objective_is_eq5() -> None:
    """Inside the bracket only objective 2 counts; outside w_p (f1 - h_o)^2 is added; failure = f_p."""
    f = np.array([0.30, 2.0])
    assert binned_objective(f, False, centre=0.3125, half_width=0.03125, w_p=5000, f_p=1e5) == 2.0
    out = binned_objective(np.array([0.40, 2.0]), False, 0.3125, 0.03125, 5000, 1e5)
    assert np.isclose(out, 2.0 + 5000 * 0.0875**2)
    assert binned_objective(f, True, 0.3125, 0.03125, 5000, 1e5) == 1e5


def _run(cfg: dict, seed: int = 0, n_var: int = 5) -> tuple[BSOOSearcher, ZDT1Task, list]:
    task = ZDT1Task({"task": {"n_var": n_var}})
    s = BSOOSearcher(task.problem(), cfg, seed)
    evs = [e for _, b in run_batches(s, task, cfg.get("batch", 16), seed) for e in b]
    return s, task, evs


def test_sweep_starts_at_the_input_controllers_bin_and_warm_starts() -> None:
    """The default point has f1 = 0.5: bins 2, 3 then 1, 0 (of 4); each bin starts at its neighbour's optimum."""
    s, _, _ = _run({"budget": 4 * 5 * 8 + 1, "batch": 8, "n_bins": 4, "popsize": 8, "bin_low": 0.0, "bin_high": 1.0})
    assert s.order == [2, 3, 1, 0]
    assert s._start_from == {2: -1, 3: 2, 1: 2, 0: 1}
    summary = s.summary()
    np.testing.assert_array_equal(summary["bin_order"], [2, 3, 1, 0])
    # the first generation of bin 3 is centred on bin 2's best point (sigma0 = 0.015 around it)
    X, bins = summary["X"], summary["bin_of_eval"]
    best2 = summary["bin_best_X"][list(summary["bins"]).index(2)]
    first3 = X[bins == 3][:8]
    assert np.abs(first3 - best2).max() < 0.1


def test_bins_end_inside_their_brackets() -> None:
    s, _, _ = _run({"budget": 16 * 30 * 8 + 1, "batch": 8, "n_bins": 16, "popsize": 8, "bin_low": 0.0, "bin_high": 1.0})
    summary = s.summary()
    f1 = summary["bin_best_objectives"][:, 0]
    lo, hi = summary["bin_edges"][summary["bins"]], summary["bin_edges"][summary["bins"] + 1]
    assert np.mean((f1 >= lo - 1e-9) & (f1 <= hi + 1e-9)) >= 0.75


def test_stall_rule_stops_a_bin() -> None:
    """With an epsilon no improvement can beat, every bin stops after stall_generations + 1 generations."""
    s, _, _ = _run({"budget": 10_000, "batch": 4, "n_bins": 3, "popsize": 4, "bin_low": 0.0, "bin_high": 1.0,
                    "stall_generations": 3, "eps": 1e9})
    np.testing.assert_array_equal(s.summary()["bin_generations"], [4, 4, 4])
    assert s.finished() and s.n_asked == 1 + 3 * 4 * 4


def test_generation_cap_stops_a_bin() -> None:
    s, _, _ = _run({"budget": 10_000, "batch": 4, "n_bins": 2, "popsize": 4, "bin_low": 0.0, "bin_high": 1.0,
                    "max_generations": 2})
    np.testing.assert_array_equal(s.summary()["bin_generations"], [2, 2])


def test_budget_is_shared_by_the_bins() -> None:
    s, _, _ = _run({"budget": 1 + 4 * 3 * 8, "batch": 8, "n_bins": 4, "popsize": 8, "bin_low": 0.0, "bin_high": 1.0})
    np.testing.assert_array_equal(s.summary()["bin_generations"], [3, 3, 3, 3])


def test_sampled_range_spans_the_sample() -> None:
    s, _, evs = _run({"budget": 40, "batch": 8, "n_bins": 4, "popsize": 8, "range_samples": 7})
    f1 = [e.objectives[0] for e in evs[:8]]
    np.testing.assert_allclose(s.edges[[0, -1]], [min(f1), max(f1)])


def test_needs_two_objectives() -> None:
    from jt_tasks.strategy_landscape import StrategyLandscapeTask

    with pytest.raises(JtError, match="two objectives"):
        BSOOSearcher(StrategyLandscapeTask({"task": {}}).problem(), {}, 0)
