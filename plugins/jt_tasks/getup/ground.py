"""The ground frame of the get-up: where a pose rests (its lowest point ``CLEARANCE`` above the
ground), shared by the start poses (``initial``) and the feature curves' heights (``curves``)."""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

CLEARANCE = 0.005  #: m between the lowest point of a start pose and the ground (ours)


@functools.lru_cache(maxsize=1)
def _kinematic_body() -> Any:
    from toolkit.motion.kinematics import kinematic_body
    from toolkit.motion.skeletons import HUMANOID

    return kinematic_body(HUMANOID)


def lowest_point(q: np.ndarray) -> float:
    """Lowest height of the humanoid's bounding boxes in pose ``q`` (a kinematic copy, never stepped)."""
    return _kinematic_body().lowest_point(np.asarray(q, dtype=np.float64))


def lift_to_ground(q: np.ndarray, ground: float = 0.0, clearance: float = CLEARANCE) -> np.ndarray:
    """``q`` moved up or down so that its lowest point is ``clearance`` above ``ground``."""
    q = np.array(q, dtype=np.float64)
    q[1] += ground + clearance - lowest_point(q)
    return q
