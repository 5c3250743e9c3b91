"""A known constraint of the box (``SearchProblem.constraint``): searchers that honour it never
propose a point outside it, the others refuse it in one line, and the weight models are right."""

from __future__ import annotations

import numpy as np
import pytest

from toolkit.errors import JtError
from toolkit.interfaces.searcher import Param, SearchProblem, Space
from toolkit.interfaces.task import Evaluation


def _margin(X: np.ndarray) -> np.ndarray:
    """Feasible above the line x + y = 1 (half of the unit square, its far corner (0, 0) excluded)."""
    X = np.atleast_2d(X)
    return X[:, 0] + X[:, 1] - 1.0


def _problem(constraint=_margin) -> SearchProblem:
    space = Space((Param("x", 0.0, 1.0), Param("y", 0.0, 1.0)))
    return SearchProblem(space=space, n_features=1, feature_low=[-1.0], feature_high=[1.0],
                         constraint=constraint, constraint_name="x + y >= 1")


def _feature(x: np.ndarray) -> float:
    return float(np.sin(3.0 * x[0]) * np.cos(2.0 * x[1]))


def _run(cls, cfg: dict, seed: int = 0) -> np.ndarray:
    s = cls(_problem(), cfg, seed)
    points = []
    while not s.finished():
        X = s.ask(int(cfg.get("batch", 1)))
        s.tell(X, [Evaluation(features=[_feature(x)]) for x in X])
        points.extend(X)
    return np.array(points)


@pytest.mark.parametrize("cfg", [{"budget": 12}, {"budget": 12, "batch": 3}, {"budget": 12, "n_init": 5, "init_method": "sobol"}])
def test_bds_keeps_every_pick_within_the_constraint(cfg) -> None:
    from jt_searchers.bds import BDSSearcher

    X = _run(BDSSearcher, cfg)
    assert len(X) == 12 and np.all(_margin(X) >= 0.0), X[_margin(X) < 0]
    np.testing.assert_array_equal(X, _run(BDSSearcher, cfg))  # same seed, same picks


def test_unconstrained_bds_does_go_outside() -> None:
    """The same search without the constraint picks points the constraint excludes (the test above
    could not pass by construction)."""
    from jt_searchers.bds import BDSSearcher

    s = BDSSearcher(_problem(constraint=None), {"budget": 12}, 0)
    X = []
    while not s.finished():
        x = s.ask(1)
        s.tell(x, [Evaluation(features=[_feature(x[0])])])
        X.extend(x)
    assert np.any(_margin(np.array(X)) < 0.0)


@pytest.mark.parametrize("method", ["uniform", "sobol"])
def test_random_search_samples_within_the_constraint(method) -> None:
    from jt_searchers.base import unit_samples
    from jt_searchers.random_search import RandomSearcher

    X = _run(RandomSearcher, {"budget": 40, "method": method}, seed=3)
    assert len(X) == 40 and np.all(_margin(X) >= 0.0)
    np.testing.assert_array_equal(X, _run(RandomSearcher, {"budget": 40, "method": method}, seed=3))
    # the feasible points of the unconstrained design come first, in order
    plain = unit_samples(40, 2, 3, method)
    kept = plain[_margin(plain) >= 0.0]
    np.testing.assert_allclose(X[: len(kept)], kept)


def test_a_constraint_with_no_feasible_point_is_one_line() -> None:
    from jt_searchers.random_search import RandomSearcher

    with pytest.raises(JtError, match="x \\+ y >= 1 leaves \\(almost\\) no point"):
        RandomSearcher(_problem(lambda X: -np.ones(len(np.atleast_2d(X)))), {"budget": 4}, 0)


@pytest.mark.parametrize("name", ["rmoo", "bsoo"])
def test_searchers_that_cannot_keep_to_it_refuse(name) -> None:
    from toolkit import plugins

    problem = SearchProblem(space=_problem().space, n_objectives=2, reference_point=[2.0, 2.0],
                            constraint=_margin, constraint_name="x + y >= 1")
    with pytest.raises(JtError, match=f"search={name} cannot keep to the task's constraint \\(x \\+ y >= 1\\)"):
        plugins.load("search", name)(problem, {"budget": 4}, 0)


def test_weights_multiply_and_their_gradient_matches_finite_differences() -> None:
    from jt_searchers.base import UnitBox
    from jt_searchers.feasibility import KnownConstraint, Product, combine, feasibility

    problem = _problem()
    known = KnownConstraint(problem, UnitBox(problem))
    np.testing.assert_array_equal(known(np.array([[0.2, 0.2], [0.6, 0.6]])), [0.0, 1.0])
    learned = feasibility(np.array([[0.9, 0.9], [0.3, 0.9]]), np.array([True, False]), np.array([0.4, 0.4]))
    both = combine(learned, known)
    assert isinstance(both, Product) and combine(None, known) is known and combine(None, None) is None
    u = np.array([0.55, 0.8])  # inside the constraint: the product rule reduces to the learned gradient
    v, g = both.value_and_grad(u)
    assert v == pytest.approx(float(learned(u[None])[0]))
    h = 1e-6
    fd = [(both(np.array([u + h * e]))[0] - both(np.array([u - h * e]))[0]) / (2 * h) for e in np.eye(2)]
    np.testing.assert_allclose(g, fd, rtol=1e-4, atol=1e-7)
    assert both(np.array([[0.1, 0.1]]))[0] == 0.0  # outside: zero whatever the learned model says
