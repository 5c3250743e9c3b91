"""``task=strategy_landscape``: cells, plateaus, noise, failures, counting, config."""

from __future__ import annotations

import dataclasses

from pathlib import Path

import numpy as np
import pytest
from omegaconf import OmegaConf

from jt_tasks.strategy_landscape import StrategyLandscapeTask, count_distinct
from toolkit.errors import JtError
from toolkit.interfaces.task import EvalContext


def _eval(task: StrategyLandscapeTask, x: np.ndarray, seed: int = 0):
    return task.evaluate(task.problem().space.to_dict(x), EvalContext(0, seed, Path(".")))


def test_problem_box_and_features() -> None:
    task = StrategyLandscapeTask({"task": {"dims": 3, "n_features": 2, "low": -2.0, "high": 2.0}})
    p = task.problem()
    assert p.space.dim == 3 and p.space.lows == [-2.0] * 3 and p.space.highs == [2.0] * 3
    assert p.n_features == 2 and p.feature_low == [0.0, 0.0] and p.feature_high == [1.0, 1.0]
    assert p.distinct_threshold == 0.1


@pytest.mark.parametrize("layout", ["quantised", "voronoi"])
def test_cells_are_unequal_and_plateaus_separated(layout: str) -> None:
    task = StrategyLandscapeTask({"task": {"layout": layout, "latent_scale": 0.12 if layout == "quantised" else 0.35}})
    vol = task.volumes()
    assert np.isclose(vol.sum(), 1.0)
    big = np.sort(vol)[::-1]
    assert big[0] > 0.2 and big[:3].sum() > 0.5  # large flat regions (000 §7.2.1)
    assert np.sum((vol > 0) & (vol < 0.05)) >= 3  # and several small strategies
    d = np.linalg.norm(task.plateaus[:, None] - task.plateaus[None], axis=-1) + 9 * np.eye(len(vol))
    assert d.min() >= task.params.min_separation


def test_evaluation_is_plateau_plus_seeded_noise() -> None:
    task = StrategyLandscapeTask({"task": {"noise": 0.05}})
    x = np.array([0.1, -0.3, 0.5, 0.2])
    k = int(task.cell((x + 1) / 2)[0])
    a, b, c = _eval(task, x, 7), _eval(task, x, 7), _eval(task, x, 8)
    assert a.metrics["strategy"] == k and not a.failed
    np.testing.assert_array_equal(a.features, b.features)
    assert not np.allclose(a.features, c.features)
    draws = np.array([_eval(task, x, s).features for s in range(400)])
    np.testing.assert_allclose(draws.mean(axis=0), task.plateaus[k], atol=0.015)
    np.testing.assert_allclose(draws.std(axis=0), 0.05, rtol=0.15)


def test_plateau_is_flat_inside_a_cell() -> None:
    task = StrategyLandscapeTask({"task": {"noise": 0.0}})
    u = np.random.default_rng(0).random((2000, 4))
    cells = task.cell(u)
    feats = np.array([_eval(task, 2 * ui - 1).features for ui in u[:200]])
    for k in np.unique(cells[:200]):
        np.testing.assert_allclose(feats[cells[:200] == k], task.plateaus[k][None].repeat(np.sum(cells[:200] == k), 0))


def test_failing_cells_return_failures() -> None:
    task = StrategyLandscapeTask({"task": {"n_failing": 3}})
    assert len(task.failing) == 3
    smallest = set(np.argsort(task.volumes(), kind="stable")[:3].tolist())
    assert task.failing == smallest
    u = np.random.default_rng(1).random((20000, 4))
    inside = u[np.isin(task.cell(u), list(task.failing))]
    if len(inside):
        ev = _eval(task, 2 * inside[0] - 1)
        assert ev.failed and len(ev.features) == 0


def test_summarize_counts_distinct_strategies() -> None:
    task = StrategyLandscapeTask({"task": {"noise": 0.01}})
    u = np.random.default_rng(2).random((30, 4))
    evs = [_eval(task, 2 * ui - 1, i) for i, ui in enumerate(u)]
    cells = task.cell(u)
    out = task.summarize(evs, Path("."))
    assert out["distinct_strategies"] == len(set(cells.tolist()))
    assert out["distinct_at_10"] == len(set(cells[:10].tolist()))
    assert out["distinct_by_features"] == out["distinct_strategies"]  # threshold separates the plateaus


def test_count_distinct_leader_clustering() -> None:
    assert count_distinct([[0.0], [0.05], [0.2], [0.26], [1.0]], 0.1) == 3


def test_config_from_the_composed_run_config() -> None:
    node = OmegaConf.load(Path(__file__).parents[3] / "conf" / "task" / "strategy_landscape.yaml")
    task = StrategyLandscapeTask(OmegaConf.create({"task": node}))
    # the YAML holds only what it selects: the landscape of docs/searchers.md
    assert set(node) == {"name", "landscape_seed"} and node.landscape_seed == 1
    assert task.params == dataclasses.replace(StrategyLandscapeTask.Config(), landscape_seed=1)
    with pytest.raises(JtError, match="unknown key"):
        StrategyLandscapeTask({"task": {"no_such_key": 1}})
