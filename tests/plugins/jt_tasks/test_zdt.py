"""``task=zdt1``: objectives, the closed-form front hypervolume against moocore, summaries."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from omegaconf import OmegaConf

from jt_tasks.zdt import ZDT1Task, hypervolume, true_hypervolume, zdt1
from toolkit.interfaces.task import EvalContext


def test_objectives_at_known_points() -> None:
    np.testing.assert_allclose(zdt1(np.zeros(30)), [0.0, 1.0])
    np.testing.assert_allclose(zdt1(np.r_[1.0, np.zeros(29)]), [1.0, 0.0])
    x = np.r_[0.25, np.full(29, 0.5)]  # g = 5.5
    np.testing.assert_allclose(zdt1(x), [0.25, 5.5 * (1 - np.sqrt(0.25 / 5.5))])


@pytest.mark.parametrize("ref", [(11.0, 11.0), (1.1, 1.1), (1.0, 1.0), (0.5, 0.8), (2.0, 0.3)])
def test_true_hypervolume_matches_moocore_on_a_dense_front(ref: tuple) -> None:
    f1 = np.linspace(0, 1, 200_001)
    front = np.c_[f1, 1 - np.sqrt(f1)]
    np.testing.assert_allclose(hypervolume(front, ref), true_hypervolume(ref), rtol=1e-4, atol=1e-6)


def test_reference_point_is_worse_than_the_whole_box() -> None:
    F = zdt1(np.random.default_rng(0).random((20000, 30)))
    F = np.vstack([F, zdt1(np.ones(30)), zdt1(np.r_[0.0, np.ones(29)])])
    assert np.all(F < 11.0)


def test_summarize_hypervolume_ratio() -> None:
    task = ZDT1Task({"task": {"n_var": 5}})
    space = task.problem().space
    front = [np.r_[t, np.zeros(4)] for t in np.linspace(0, 1, 2001)]
    evs = [task.evaluate(space.to_dict(x), EvalContext(i, i, Path("."))) for i, x in enumerate(front)]
    out = task.summarize(evs, Path("."))
    assert 0.999 < out["hv_ratio"] <= 1.0 + 1e-9
    np.testing.assert_allclose(out["hypervolume"], 121 - 1 / 3, rtol=1e-3)
    rand = [task.evaluate(space.to_dict(x), EvalContext(i, i, Path(".")))
            for i, x in enumerate(np.random.default_rng(0).random((50, 5)))]
    assert task.summarize(rand, Path("."))["hv_ratio"] < 0.95


def test_problem_and_config() -> None:
    node = OmegaConf.load(Path(__file__).parents[3] / "conf" / "task" / "zdt1.yaml")
    task = ZDT1Task(OmegaConf.create({"task": node}))
    p = task.problem()
    assert p.space.dim == 30 and p.n_objectives == 2 and list(p.reference_point) == [11.0, 11.0]
    assert task.params == ZDT1Task.Config()
