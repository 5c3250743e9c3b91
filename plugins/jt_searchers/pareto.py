"""Pareto utilities (``004`` §4.2.2–4.2.3): non-dominated ranks, hypervolume, eq 16 ordering.

Objectives are minimised. Non-dominated sorting and hypervolumes come from ``moocore``
(``pareto_rank``, ``hypervolume``, ``hv_contributions``). Failed samples carry no objectives: they
rank after every successful one.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np


def hypervolume(F: np.ndarray, ref: Sequence[float]) -> float:
    """Hypervolume of the points ``F`` ``(n, M)`` dominated region up to ``ref`` ``(M,)`` (eq 13).

    Non-finite rows and points not strictly better than ``ref`` in every objective add nothing.
    """
    import moocore

    F = np.asarray(F, dtype=float).reshape(-1, len(ref))
    ref = np.asarray(ref, dtype=float)
    F = F[np.all(np.isfinite(F), axis=1) & np.all(F < ref, axis=1)]
    return float(moocore.hypervolume(F, ref=ref)) if len(F) else 0.0


def ranks(F: np.ndarray) -> np.ndarray:
    """Non-dominance level of each row of ``F`` ``(n, M)`` → ``(n,)``, 0 = non-dominated (eqs 10–12)."""
    import moocore

    F = np.asarray(F, dtype=float)
    return np.asarray(moocore.pareto_rank(F), dtype=int) if len(F) else np.zeros(0, dtype=int)


def contributions(front: np.ndarray, rel_tol: float = 1e-9) -> np.ndarray:
    """Hypervolume contribution of each point of a mutually non-dominated set (eq 15), boundary = inf.

    ``004`` §4.2.3: boundary elements get an infinite contribution; they are the ones whose
    contribution changes when the reference point moves. The contributions are computed for two
    reference points beyond the set's worst values; those that differ are the boundary points. The
    others do not depend on the reference point, which is why no fixed one is needed here.

    Args:
        front: objective vectors ``(n, M)``, mutually non-dominated.
        rel_tol: relative tolerance when comparing the two contributions.

    Returns:
        Contributions ``(n,)``; duplicates of a point contribute 0 (moocore's convention).
    """
    import moocore

    front = np.asarray(front, dtype=float)
    n = len(front)
    if n <= 2:
        return np.full(n, np.inf)
    span = np.maximum(front.max(axis=0) - front.min(axis=0), 1e-12)
    ref1 = front.max(axis=0) + span
    ref2 = front.max(axis=0) + 2.0 * span
    c1 = np.asarray(moocore.hv_contributions(front, ref=ref1), dtype=float)
    c2 = np.asarray(moocore.hv_contributions(front, ref=ref2), dtype=float)
    scale = float(np.prod(span))
    boundary = np.abs(c2 - c1) > rel_tol * max(scale, 1e-300)
    out = c1.copy()
    out[boundary] = np.inf
    return out


def selection_order(F: np.ndarray, failed: np.ndarray) -> np.ndarray:
    """Indices of the rows of ``F`` ``(n, M)``, best first, by ``004`` eq 16.

    Lower non-dominance rank first; within a rank, larger hypervolume contribution to that rank's
    front first; failed rows (``failed`` ``(n,)`` bool) last. Remaining ties keep index order, so
    the order is deterministic.
    """
    F = np.asarray(F, dtype=float)
    failed = np.asarray(failed, dtype=bool) | ~np.all(np.isfinite(F), axis=1)
    n = len(F)
    rank = np.full(n, n + 1, dtype=int)
    contrib = np.full(n, -np.inf)
    ok = np.flatnonzero(~failed)
    if len(ok):
        r = ranks(F[ok])
        rank[ok] = r
        for level in np.unique(r):
            members = ok[r == level]
            contrib[members] = contributions(F[members])
    return np.lexsort((np.arange(n), -contrib, rank))
