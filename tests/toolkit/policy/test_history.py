"""The policy tasks' shared per-iteration history and metric plumbing (toolkit.policy.history)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from toolkit.policy.episodes import Rollout
from toolkit.policy.history import IterationHistory, base_metrics, finite, mean_of, measured, numbers


def stats(*episodes: dict) -> SimpleNamespace:
    return SimpleNamespace(episodes=list(episodes))


def test_rows_are_means_of_finished_episodes_and_live_in_extra():
    extra: dict = {}
    h = IterationHistory(extra, "goal_history", ("r_goal", "took_off"), 100)
    h.on_iteration(1, 10, stats({"r_goal": 0.5, "took_off": 1.0}, {"r_goal": 0.1}))
    h.on_iteration(2, 20, stats())  # no episode ended: nan, not 0
    rows = extra["goal_history"]
    assert rows.shape == (2, 3)
    np.testing.assert_allclose(rows[0], [10, 0.3, 0.5])
    assert rows[1, 0] == 20 and math.isnan(rows[1, 1]) and math.isnan(rows[1, 2])


def test_a_resumed_history_continues_the_saved_rows():
    extra = {"h": np.array([[10.0, 1.0]])}  # what a checkpoint's extra brings back
    IterationHistory(extra, "h", ("x",), 100).on_iteration(2, 20, stats({"x": 3.0}))
    np.testing.assert_allclose(extra["h"], [[10, 1], [20, 3]])


def test_curves_rename_prefix_and_drop_missing_values():
    extra: dict = {}
    h = IterationHistory(extra, "k", ("a", "b"), 100)
    h.on_iteration(1, 5, stats({"a": 1.0, "b": 2.0}))
    h.on_iteration(2, 9, stats())
    assert h.curves(extra, {"a": "alpha"}, prefix="train_") == {"alpha": [(5, 1.0)], "train_b": [(5, 2.0)]}


def test_a_custom_row_a_chained_hook_and_the_progress_figure():
    seen, calls = [], []
    h = IterationHistory({}, "k", ("success",), 40, progress=lambda f, m: seen.append((f, m)),
                         row=lambda eps, st: [len(eps) / 4], shown=("success", ".2f", "none yet"),
                         then=lambda it, s, st: calls.append(it) or {"level": 2})
    assert h.on_iteration(1, 10, stats({}, {})) == {"level": 2}  # the chained hook's env attributes
    assert calls == [1] and seen == [(0.25, "success 0.50")]
    h2 = IterationHistory({}, "k", ("success",), 40, progress=lambda f, m: seen.append((f, m)),
                          shown=("success", ".2f", "none yet"))
    h2.on_iteration(1, 80, stats())
    assert seen[-1] == (1.0, "success none yet")


def test_metric_plumbing():
    assert mean_of([{"a": 1.0}, {}], "a") == 0.5 and math.isnan(mean_of([], "a"))
    assert numbers({"x": 1, "y": 2.5, "reason": "fell", "ok": True}) == {"x": 1.0, "y": 2.5, "ok": 1.0}
    assert finite({"a": 1.0, "b": math.nan, "c": math.inf}) == {"a": 1.0}
    res = SimpleNamespace(history={"mean_return": [1.0, 2.0, math.nan]}, samples=4096, iterations=2)
    m = base_metrics(Rollout(return_=3.5, info={}, steps=7),
                     SimpleNamespace(result=res, samples_per_s=100.0, wall_s=41.0))
    assert m == {"mean_return": 3.5, "train_mean_return": 2.0, "samples": 4096.0, "iterations": 2.0,
                 "samples_per_s": 100.0, "train_wall_s": 41.0}


def test_measured_puts_the_task_metrics_first_drops_nonfinite_and_leads_the_curves_with_the_return():
    from toolkit.policy.train import TIMES

    res = SimpleNamespace(history={"mean_return": [1.0, math.nan, 3.0]}, samples=96, iterations=3,
                          extra={TIMES: [10.0, 11.0, 12.0]})
    cfg = SimpleNamespace(n_workers=1, envs_per_worker=2, samples_per_iteration=31)  # 32 per iteration
    trained = SimpleNamespace(result=res, config=cfg, samples_per_s=math.nan, wall_s=5.0)
    ro = Rollout(return_=2.5, info={}, steps=4)
    metrics, history = measured(ro, trained, {"height": 1.5, "angle": math.nan}, {"own": [(32, 0.1)]})
    assert list(metrics) == ["height", "mean_return", "train_mean_return", "samples", "iterations",
                             "train_wall_s"]  # nan angle and samples_per_s left out
    assert metrics["mean_return"] == 2.5 and metrics["train_mean_return"] == 3.0
    assert list(history) == ["mean_return", "own"]
    assert history["mean_return"] == [(32, 1.0, 10.0), (96, 3.0, 12.0)]  # iterations without an episode left out
    kept, _ = measured(ro, trained, {"angle": math.nan}, keep_nonfinite=True)
    assert math.isnan(kept["angle"]) and math.isnan(kept["samples_per_s"])
