"""BDS and evaluations without a feature (``jt_searchers.feasibility``, ``search.failures``).

The probability model against its definition and finite differences, then the laptop high-jump
run replayed from its recorded outcomes: the kriging-believer rule reproduces the recorded picks
(the failed corner sampled three times), the ``avoid`` rule moves away from it.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.stats import norm

from jt_searchers.bds import BDSSearcher
from jt_searchers.feasibility import Feasibility, feasibility
from jt_tasks.jumping.features import angle_distance
from jt_tasks.strategy_landscape import StrategyLandscapeTask
from toolkit.errors import JtError
from toolkit.interfaces.searcher import Param, SearchProblem, Space
from toolkit.interfaces.task import Evaluation

GOLDEN = Path(__file__).parent / "golden" / "bds_laptop_highjump.json"
FAST = {"direct_maxfun": 400, "n_mc": 64, "lbfgs_starts": 4, "gp_restarts": 1}


def _model() -> tuple[Feasibility, np.ndarray]:
    U = np.array([[0.1, 0.1], [0.9, 0.9], [0.5, 0.2]])
    return Feasibility(U, np.array([True, False, True]), np.array([0.2, 0.2])), U


def test_probability_is_low_at_failures_half_far_away_high_at_successes() -> None:
    p, U = _model()
    at = p(U)
    assert at[1] < 1e-3 and at[0] > 0.99 and at[2] > 0.99
    assert abs(float(p(np.array([[0.1, 0.95]]))[0]) - 0.5) < 0.05  # ~4 length scales from every point
    mean, std = p.gp.predict_standardised(np.array([[0.7, 0.7]]))
    assert float(p(np.array([[0.7, 0.7]]))[0]) == pytest.approx(norm.cdf(mean[0, 0] / std[0]))


def test_probability_gradient_matches_finite_differences() -> None:
    p, _ = _model()
    u, h = np.array([0.7, 0.6]), 1e-6
    value, grad = p.value_and_grad(u)
    assert value == pytest.approx(float(p(u[None])[0]), abs=1e-12)
    fd = [(float(p((u + h * e)[None])[0]) - float(p((u - h * e)[None])[0])) / (2 * h) for e in np.eye(2)]
    np.testing.assert_allclose(grad, fd, rtol=1e-5, atol=1e-8)


def test_no_model_until_something_fails() -> None:
    assert feasibility(np.random.default_rng(0).random((4, 2)), np.ones(4, bool), np.ones(2)) is None


def test_unknown_rule_is_one_line() -> None:
    task = StrategyLandscapeTask({"task": {}})
    with pytest.raises(JtError, match="search.failures='never'.*avoid, believe"):
        BDSSearcher(task.problem(), {"failures": "never"}, 0)


# ---- the laptop high-jump run, replayed -----------------------------------------------------------


def _replay(rule: str, tolerance: float) -> tuple[list[np.ndarray], list[str]]:
    """Ask BDS one point at a time, telling each the recorded outcome while it stays on the record."""
    g = json.loads(GOLDEN.read_text())
    space = Space(tuple(Param(n, lo, hi) for n, lo, hi in zip(g["names"], g["low"], g["high"])))
    problem = SearchProblem(space=space, n_features=1, feature_low=[0.0], feature_high=[math.pi],
                            feature_distance=angle_distance)
    s = BDSSearcher(problem, {"budget": 10, "failures": rule}, g["seed"])
    picks = []
    for x_rec, f in zip(np.array(g["x"]), g["features"]):
        x = s.ask(1)[0]
        picks.append(x)
        if np.abs(x - x_rec).max() > tolerance:
            break
        s.tell(x[None], [Evaluation(features=[] if f is None else [f], failed=f is None)])
    return picks, s.kinds


def _unit_distance_to_failures(x: np.ndarray) -> float:
    g = json.loads(GOLDEN.read_text())
    lo, hi = np.array(g["low"]), np.array(g["high"])
    fails = np.array([xr for xr, f in zip(g["x"], g["features"]) if f is None])
    return float(np.min(np.abs((fails - x) / (hi - lo)).max(axis=1)))


def test_believe_reproduces_the_recorded_laptop_run() -> None:
    g = json.loads(GOLDEN.read_text())
    picks, kinds = _replay("believe", 1e-4)
    assert len(picks) == 10 and kinds == g["kinds"]
    np.testing.assert_allclose(np.array(picks), np.array(g["x"]), atol=1e-4)
    assert _unit_distance_to_failures(picks[7]) < 0.01  # the failed corner, sampled again


def test_avoid_leaves_the_failed_corner() -> None:
    """Told the record while it stays within 5 % of it, the diversity picks go elsewhere."""
    picks, kinds = _replay("avoid", 0.05)
    assert kinds[6:len(picks)] and all(k == "diversity" for k in kinds[6:len(picks)])
    assert len(picks) >= 8  # pick 6 stays on the record (within 5 %), pick 7 leaves it
    assert _unit_distance_to_failures(picks[7]) > 0.25
