"""Pareto utilities (004 §4.2.2–4.2.3) against brute force and hand-computed hypervolumes."""

from __future__ import annotations

import itertools

import numpy as np

from jt_searchers.pareto import contributions, hypervolume, ranks, selection_order


def _brute_ranks(F: np.ndarray) -> np.ndarray:
    """eqs 10–12 literally: peel off the non-dominated set, level by level."""
    left, level, out = set(range(len(F))), 0, np.zeros(len(F), dtype=int)
    while left:
        nd = {i for i in left if not any(np.all(F[j] <= F[i]) and np.any(F[j] < F[i]) for j in left)}
        for i in nd:
            out[i] = level
        left -= nd
        level += 1
    return out


def test_ranks_match_brute_force() -> None:
    F = np.random.default_rng(0).integers(0, 6, size=(40, 3)).astype(float)
    np.testing.assert_array_equal(ranks(F), _brute_ranks(F))


def test_hypervolume_of_a_staircase() -> None:
    F = np.array([[1.0, 3.0], [2.0, 2.0], [3.0, 1.0], [3.5, 3.5], [5.0, 0.5]])
    # union of [1,4]x[3,4], [2,4]x[2,4], [3,4]x[1,4]; (3.5,3.5) dominated; (5,0.5) beyond the reference
    assert hypervolume(F, [4.0, 4.0]) == 3.0 + 2.0 + 1.0
    assert hypervolume(np.array([[np.nan, 1.0]]), [4.0, 4.0]) == 0.0


def test_contributions_inner_exact_boundary_infinite() -> None:
    front = np.array([[0.0, 3.0], [1.0, 1.5], [2.0, 1.0], [3.0, 0.0]])
    c = contributions(front)
    assert np.isinf(c[0]) and np.isinf(c[3])  # extremes: depend on the reference point (004 §4.2.3)
    # inner points: exclusive rectangles (1-0)*(3-1.5)... computed by hand: (2-1)*(3-1.5)=1.5, (3-2)*(1.5-1)=0.5
    np.testing.assert_allclose(c[1:3], [1.5, 0.5])


def test_contributions_agree_with_leave_one_out_hypervolume() -> None:
    rng = np.random.default_rng(1)
    t = np.sort(rng.random(8))
    front = np.c_[t, 1 - np.sqrt(t)]  # mutually non-dominated
    c = contributions(front)
    ref = front.max(axis=0) + 1.0
    total = hypervolume(front, ref)
    for i in np.flatnonzero(np.isfinite(c)):
        np.testing.assert_allclose(c[i], total - hypervolume(np.delete(front, i, 0), ref), rtol=1e-9)


def test_selection_order_is_eq16() -> None:
    F = np.array([
        [2.0, 2.0],  # 0: rank 1 (dominated by 3)
        [0.0, 4.0],  # 1: rank 0, boundary
        [4.0, 0.0],  # 2: rank 0, boundary
        [1.5, 1.5],  # 3: rank 0, contribution (3 - 1.5) * (4 - 1.5) = 3.75
        [3.0, 1.0],  # 4: rank 0, contribution (4 - 3) * (1.5 - 1) = 0.5
        [9.0, 9.0],  # 5: failed
    ])
    failed = np.array([False] * 5 + [True])
    np.testing.assert_allclose(contributions(F[[1, 3, 4, 2]]), [np.inf, 3.75, 0.5, np.inf])
    assert list(ranks(F[:5])) == [1, 0, 0, 0, 0]
    # rank first, then larger contribution (boundary = inf, ties by index), failed last
    assert list(selection_order(F, failed)) == [1, 2, 3, 4, 0, 5]


def test_selection_order_is_deterministic_on_ties() -> None:
    F = np.ones((5, 2))
    for perm in itertools.permutations(range(3)):
        assert list(selection_order(F[list(perm) + [3, 4]], np.zeros(5, bool))) == [0, 1, 2, 3, 4]
