"""Distances between strategy feature vectors (``SearchProblem.feature_distance``).

Every helper here is vectorised: ``d(a, b)`` takes arrays ``(..., n_features)`` that broadcast
against each other and returns ``(...)``. BDS evaluates the distance between thousands of
Monte-Carlo feature samples and the observed features per acquisition call (``000`` eq 7), so a
task should supply a vectorised distance; ``pairwise`` falls back to a Python loop for a scalar one.
"""

from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

Distance = Callable[[Any, Any], Any]


def euclidean(a: Any, b: Any) -> np.ndarray:
    """Euclidean distance ``||a - b||`` over the last axis ``(..., n)`` → ``(...)``."""
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    return np.sqrt(np.einsum("...i,...i->...", d, d))


def wrap_angle(x: Any) -> np.ndarray:
    """Angles wrapped into ``[-pi, pi)``."""
    return np.mod(np.asarray(x, dtype=float) + np.pi, 2.0 * np.pi) - np.pi


def angle(a: Any, b: Any) -> np.ndarray:
    """Distance between vectors of angles (radians) with wrap-around per component.

    Each component difference is wrapped into ``[-pi, pi)`` before taking the Euclidean norm, so
    ``angle([pi - 0.1], [-pi + 0.1]) == 0.2``.

    Args:
        a: angles ``(..., n)``.
        b: angles ``(..., n)``.

    Returns:
        Distances ``(...)``, each in ``[0, pi * sqrt(n)]``.
    """
    return np.linalg.norm(wrap_angle(np.asarray(a, dtype=float) - np.asarray(b, dtype=float)), axis=-1)


def quaternion(a: Any, b: Any) -> np.ndarray:
    """Rotation angle between unit quaternions (any component order, the same for both).

    ``q`` and ``-q`` are the same rotation, so the distance is ``2 * arccos(|<a, b>|)`` — the
    angle of the relative rotation, in ``[0, pi]``. Inputs are normalised first.

    Args:
        a: quaternions ``(..., 4)``.
        b: quaternions ``(..., 4)``.

    Returns:
        Distances ``(...)`` in radians.
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    dot = np.abs(np.sum(a * b, axis=-1))
    return 2.0 * np.arccos(np.clip(dot, 0.0, 1.0))


BY_NAME: dict[str, Distance] = {"euclidean": euclidean, "angle": angle, "quaternion": quaternion}


def resolve(distance: Optional[Distance | str]) -> Distance:
    """A distance function from ``None`` (Euclidean), a name in ``BY_NAME``, or a callable."""
    if distance is None:
        return euclidean
    if isinstance(distance, str):
        try:
            return BY_NAME[distance]
        except KeyError:
            raise ValueError(f"unknown feature distance {distance!r}; known: {sorted(BY_NAME)}") from None
    return distance


def pairwise(distance: Distance, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """All distances between rows of ``a`` ``(n, m)`` and rows of ``b`` ``(k, m)`` → ``(n, k)``.

    Tries the vectorised call ``distance(a[:, None], b[None])`` first; if that raises or returns
    the wrong shape (a scalar-only function), loops over the pairs.
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    try:
        d = np.asarray(distance(a[:, None, :], b[None, :, :]), dtype=float)
        if d.shape == (len(a), len(b)):
            return d
    except Exception:  # a scalar-only distance: fall through to the loop
        pass
    return np.array([[float(distance(x, y)) for y in b] for x in a]).reshape(len(a), len(b))
