"""Style measures of a motion (``002`` §3.3): kinetic energy and body volume.

What the style reward terms (``jt_rewards.style``) reward and what a task reports of a rollout
(``task=spacetime``'s ``style_*`` / ``ref_*`` metrics) are the same two numbers, so they live
here, beside the other motion features, for both.
"""

from __future__ import annotations

import numpy as np


def kinetic_energy(link_vel: np.ndarray, masses: np.ndarray, rotational: float = 0.0) -> float:
    """``Σ ½ m |v|² + rotational − ½ |P_xz|² / M`` (J), y-up world: the bodies' kinetic energy less
    the horizontal motion of the centre of mass (``002`` eq 4's E).

    Args:
        link_vel: body velocities ``(n, 3)``; masses: ``(n,)``; rotational: the rotational part (J).
    """
    v = np.asarray(link_vel, dtype=float).reshape(-1, 3)
    m = np.asarray(masses, dtype=float).reshape(-1)
    p = m @ v
    return float(0.5 * np.sum(m * np.sum(v * v, axis=1)) + rotational - 0.5 * (p[0] ** 2 + p[2] ** 2) / m.sum())


def hull_volume(points: np.ndarray) -> float:
    """Volume (m³) of the convex hull of ``points`` ``(n, 3)`` (``002`` eq 5's V); 0 when they span
    no volume."""
    from scipy.spatial import ConvexHull, QhullError

    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    try:
        return float(ConvexHull(pts).volume)
    except (QhullError, ValueError):
        return 0.0
