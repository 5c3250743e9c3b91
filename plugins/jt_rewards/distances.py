"""Feature distances for the novelty reward (``000`` eq 12): ``‖f_i − f‖`` in a chosen metric.

Each distance takes a feature ``f`` ``(d,)`` and previous features ``F`` ``(n, d)`` and returns
``(n,)``. Rotational features need their own metric (``000`` §5.1: "the feature space is
non-Euclidean as in our case with rotational features"):

* ``euclidean``: ``‖f_i − f‖₂``.
* ``angle``: every component an angle (rad); differences wrapped into ``[−π, π)`` first.
* ``quat``: ``f`` holds unit quaternions (``d = 4k``, any component order, the same for all);
  per quaternion the geodesic angle ``2·arccos|⟨q_i, q⟩|`` in ``[0, π]`` (``q`` and ``−q`` are
  the same rotation), combined over the ``k`` quaternions as a Euclidean norm.
* ``rotvec``: ``f`` holds rotation vectors (exp maps, ``d = 3k``); same geodesic angle.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

Distance = Callable[[np.ndarray, np.ndarray], np.ndarray]


def euclidean(f: np.ndarray, others: np.ndarray) -> np.ndarray:
    """``‖others_i − f‖₂`` ``(n,)`` for ``f`` ``(d,)``, ``others`` ``(n, d)``."""
    return np.linalg.norm(others - f[None, :], axis=-1)


def wrap(x: np.ndarray) -> np.ndarray:
    """Angles wrapped into ``[−π, π)``."""
    return np.mod(x + np.pi, 2.0 * np.pi) - np.pi


def angle(f: np.ndarray, others: np.ndarray) -> np.ndarray:
    """Euclidean norm of the wrapped per-component angle differences ``(n,)``."""
    return np.linalg.norm(wrap(others - f[None, :]), axis=-1)


def _geodesic(q: np.ndarray, qs: np.ndarray) -> np.ndarray:
    """Angles between unit quaternions ``q`` ``(k, 4)`` and ``qs`` ``(n, k, 4)`` → ``(n, k)``."""
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    qs = qs / np.linalg.norm(qs, axis=-1, keepdims=True)
    dot = np.abs(np.einsum("kc,nkc->nk", q, qs))
    # 2·atan2(|q_a ∧ q_b|, |<q_a, q_b>|) is accurate near 0 where arccos is not
    sin_half = np.sqrt(np.clip(1.0 - dot**2, 0.0, 1.0))
    return 2.0 * np.arctan2(sin_half, np.clip(dot, 0.0, 1.0))


def quat(f: np.ndarray, others: np.ndarray) -> np.ndarray:
    """Geodesic rotation distance between quaternion features ``(4k,)`` / ``(n, 4k)`` → ``(n,)``."""
    if f.shape[-1] % 4:
        raise ValueError(f"quat distance needs 4k feature components, got {f.shape[-1]}")
    ang = _geodesic(f.reshape(-1, 4), others.reshape(len(others), -1, 4))
    return np.linalg.norm(ang, axis=-1)


def rotvec(f: np.ndarray, others: np.ndarray) -> np.ndarray:
    """Geodesic rotation distance between rotation-vector features ``(3k,)`` / ``(n, 3k)``."""
    from toolkit.motion.rotations import quat_from_expmap

    if f.shape[-1] % 3:
        raise ValueError(f"rotvec distance needs 3k feature components, got {f.shape[-1]}")
    q = quat_from_expmap(f.reshape(-1, 3))
    qs = quat_from_expmap(others.reshape(len(others), -1, 3))
    return np.linalg.norm(_geodesic(q, qs), axis=-1)


BY_NAME: dict[str, Distance] = {"euclidean": euclidean, "angle": angle, "quat": quat, "rotvec": rotvec}


def resolve(name: str) -> Distance:
    """The distance called ``name`` (``ValueError`` listing the known ones otherwise)."""
    try:
        return BY_NAME[name]
    except KeyError:
        raise ValueError(f"unknown feature distance {name!r}; choose one of: {', '.join(BY_NAME)}") from None
