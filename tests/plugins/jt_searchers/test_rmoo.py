"""``search=rmoo`` (004 §4.2–4.3): the contract, the (1+1)-CMA-ES rules, resampling, and RMOO
against BSOO and random search on ZDT1 at equal budgets."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from toolkit.errors import JtError

from jt_searchers.bsoo import BSOOSearcher
from jt_searchers.mo_cmaes import Individual, StrategyParameters, update_covariance, update_step_size, step_of
from jt_searchers.random_search import RandomSearcher
from jt_searchers.rmoo import RMOOSearcher
from jt_tasks.zdt import ZDT1Task
from toolkit.testing.searcher import SearcherContract, run_batches
from toolkit.interfaces.task import EvalContext, Evaluation


class TestRMOO(SearcherContract):
    searcher_cls = RMOOSearcher
    cfg = {"budget": 41, "batch": 4, "mu": 4}
    batch = 4
    golden_name = "rmoo"
    golden_points = 9

    def make_task(self) -> ZDT1Task:
        return ZDT1Task({"task": {"n_var": 5}})


def test_strategy_parameters_are_igel_2007() -> None:
    p = StrategyParameters.for_dim(10)
    assert p.d == 6.0 and np.isclose(p.p_target, 1 / 5.5) and np.isclose(p.c_p, (1 / 5.5) / (2 + 1 / 5.5))
    assert np.isclose(p.c_c, 2 / 12) and np.isclose(p.c_cov, 2 / 106) and p.p_thresh == 0.44


def test_one_plus_one_cma_es_converges_on_a_sphere() -> None:
    """The single-objective (1+1)-CMA-ES built from these rules converges linearly (outside check:
    Igel et al. 2006/2007 report linear convergence on the sphere)."""
    n = 5
    par = StrategyParameters.for_dim(n)
    rng = np.random.default_rng(0)
    parent = Individual.initial(np.full(n, 0.9), 0.1, par)
    f = lambda x: float(np.sum((x - 0.5) ** 2))  # noqa: E731
    fp = f(parent.x)
    for _ in range(1500):
        child = parent.mutate(rng)
        fc = f(child.x)
        success = fc <= fp
        update_step_size(parent, success, par)
        update_step_size(child, success, par)
        if success:
            update_covariance(child, step_of(parent, child), par)
            parent, fp = child, fc
    assert fp < 1e-12


def test_step_size_grows_on_success_and_shrinks_on_failure() -> None:
    par = StrategyParameters.for_dim(4)
    a = Individual.initial(np.full(4, 0.5), 0.1, par)
    b = a.copy()
    update_step_size(a, 1.0, par)
    update_step_size(b, 0.0, par)
    assert a.sigma > 0.1 > b.sigma


class FlakyZDT1(ZDT1Task):
    """ZDT1 whose evaluations fail half the time (a seeded coin), to exercise resampling."""

    def evaluate(self, point: dict[str, float], ctx: EvalContext) -> Evaluation:
        if np.random.default_rng(ctx.seed).random() < 0.5:
            return Evaluation(failed=True, reason="fell over")
        return super().evaluate(point, ctx)


def test_at_most_three_failed_children_per_generation() -> None:
    """004 §4.3.1: failed children are re-drawn until at most 3 of the mu remain failed."""
    task = FlakyZDT1({"task": {"n_var": 5}})
    s = RMOOSearcher(task.problem(), {"budget": 400, "mu": 16}, 0)
    run_batches(s, task, 16, 0)
    summary = s.summary()
    assert s.n_resampled > 0
    per_gen = summary["failed_at_selection"]
    assert len(per_gen) >= 5 and per_gen.max() <= 3
    gens = summary["generation"]
    assert np.bincount(gens[gens > 0]).max() > 16  # some generations evaluated more than mu children


def test_initial_parents_are_copies_of_the_input_controller() -> None:
    task = ZDT1Task({"task": {"n_var": 5}})
    s = RMOOSearcher(task.problem(), {"budget": 1, "mu": 4}, 0)
    (X, _), = run_batches(s, task, 4, 0)
    np.testing.assert_allclose(X, [task.problem().space.defaults()])
    assert len(s.parents) == 4 and all(np.allclose(p.x, s.parents[0].x) for p in s.parents)


def _hv(cls: type, cfg: dict, budget: int, seed: int) -> float:
    task = ZDT1Task({"task": {}})
    s = cls(task.problem(), dict(cfg, budget=budget), seed)
    evs = [e for _, b in run_batches(s, task, 16, seed) for e in b]
    assert len(evs) == budget or s.finished()
    return task.summarize(evs, Path("."))["hv_ratio"]


def test_rmoo_beats_bsoo_and_random_on_zdt1() -> None:
    """004 §5: RMOO recovers the front with fewer samples than BSOO (ZDT1, n = 30, 1000 evaluations)."""
    hv = {name: np.mean([_hv(cls, cfg, 1000, seed) for seed in range(2)]) for name, cls, cfg in (
        ("rmoo", RMOOSearcher, {}),
        ("bsoo", BSOOSearcher, {"bin_low": 0.0, "bin_high": 1.0}),
        ("random", RandomSearcher, {}),
    )}
    assert hv["rmoo"] > hv["bsoo"] + 0.05 and hv["rmoo"] > hv["random"] + 0.05, hv


@pytest.mark.slow
def test_rmoo_front_at_larger_budgets() -> None:
    """At 5000 evaluations RMOO is within 5 % of the true front's hypervolume and far ahead of random."""
    rmoo = np.mean([_hv(RMOOSearcher, {}, 5000, seed) for seed in range(3)])
    rand = np.mean([_hv(RandomSearcher, {}, 5000, seed) for seed in range(3)])
    assert rmoo > 0.95 and rmoo > rand + 0.1


def test_success_rule_selected_counts_children_that_enter_the_parents() -> None:
    """``success=selected`` (Voss et al. 2010) also credits a child that enters the parents next to
    its own surviving parent, which ``parent`` (Igel et al. 2007) does not: on ZDT1 the parents'
    smoothed success rates come out higher. An unknown rule is one clear error."""
    task = ZDT1Task({"task": {"n_var": 5}})
    rates = {}
    for rule in ("parent", "selected"):
        s = RMOOSearcher(task.problem(), {"budget": 160, "mu": 8, "success": rule}, 0)
        run_batches(s, task, 8, 0)
        rates[rule] = np.mean([p.p_succ for p in s.parents])
    assert rates["selected"] > rates["parent"], rates
    with pytest.raises(JtError, match="search.success=better: one of parent, selected"):
        RMOOSearcher(task.problem(), {"success": "better"}, 0)
