"""Strategy features (``000`` §6.1.4): the root orientation when the CoM crosses the bar plane.

"We use the root orientation when the character's CoM lies in the vertical crossbar plane as f.
This three-dimensional root orientation serves well as a Stage 2 feature [...] For Stage 1 [...]
we only measure the angle between the character's root direction and the global up vector"
(``000`` §6.1.4); for obstacle jumps the plane is the obstacle's centre plane.

* Stage 1: ``up_angle(q)`` = angle between the root's local up axis (+y of the DeepMimic root)
  and world up, in ``[0, pi]`` (0: upright, pi: upside down).
* Stage 2: the root orientation expressed in the suite frame (normal, up, along), as a unit
  quaternion x, y, z, w with ``w >= 0`` (so that the approach angle does not change it).

``CrossingTracker`` is fed the CoM's signed distance past the plane and the root orientation at
every check; at the first sign change from before to past the plane it interpolates the
orientation (slerp) at the zero crossing.
"""

from __future__ import annotations

import functools
import math
from typing import Any, Optional

import numpy as np

from toolkit.motion import rotations as rot


def up_angle(q_root: np.ndarray) -> float:
    """Angle (rad, ``[0, pi]``) between the root's up axis and world up (+y)."""
    up = rot.quat_rotate(np.asarray(q_root, dtype=float), np.array([0.0, 1.0, 0.0]))
    return float(math.acos(max(-1.0, min(1.0, float(up[1]) / max(float(np.linalg.norm(up)), 1e-12)))))


def suite_orientation(q_root: np.ndarray, suite_rotation: np.ndarray) -> np.ndarray:
    """Root orientation in the suite frame ``(4,)`` x,y,z,w, canonical (``w >= 0``).

    Args:
        q_root: world root orientation ``(4,)``.
        suite_rotation: suite axes as columns ``(3, 3)`` (``Suite.rotation()``).
    """
    q_suite = _suite_quat(np.asarray(suite_rotation, dtype=float).tobytes())
    q = rot.quat_multiply(rot.quat_conjugate(q_suite), np.asarray(q_root, dtype=float))
    return rot.quat_canonical(rot.quat_normalize(q))


@functools.lru_cache(maxsize=64)
def _suite_quat(rotation: bytes) -> np.ndarray:
    """``matrix_to_quat`` of a suite rotation ``(3, 3)`` given as its bytes (an episode's end asks
    for the same few frames again and again); read-only."""
    q = rot.matrix_to_quat(np.frombuffer(rotation, dtype=np.float64).reshape(3, 3))
    q.flags.writeable = False
    return q


def angle_distance(a: Any, b: Any) -> np.ndarray:
    """Distance between Stage-1 features (angles in ``[0, pi]``): ``|a - b|`` over the last axis
    (Euclidean norm for vectors); the same as a wrap-around angle distance inside ``[0, pi]``."""
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    d = np.abs((d + math.pi) % (2 * math.pi) - math.pi)
    return np.linalg.norm(d, axis=-1)


class CrossingTracker:
    """Finds the first time the CoM passes the feature plane and the root orientation then.

    Attributes:
        crossed: whether the crossing happened.
        time: time of the crossing (s, interpolated).
        q_root: root orientation ``(4,)`` at the crossing (slerp between the two checks).
    """

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """Forget the previous episode."""
        self.crossed = False
        self.at_landing = False
        self.time = math.nan
        self.q_root: Optional[np.ndarray] = None
        self._prev: Optional[tuple[float, float, np.ndarray]] = None

    def update(self, t: float, signed_distance: float, q_root: np.ndarray) -> bool:
        """Feed one check; True when this call found the crossing.

        Args:
            t: time (s).
            signed_distance: CoM distance past the plane (negative before it).
            q_root: world root orientation ``(4,)``.
        """
        q_root = np.asarray(q_root, dtype=float)
        found = False
        if not self.crossed and self._prev is not None:
            t0, d0, q0 = self._prev
            if d0 < 0.0 <= signed_distance:
                u = d0 / (d0 - signed_distance) if signed_distance != d0 else 1.0
                self.crossed, found = True, True
                self.time = t0 + u * (t - t0)
                self.q_root = rot.quat_normalize(rot.quat_slerp(q0, q_root, u))
        self._prev = (float(t), float(signed_distance), q_root.copy())
        return found

    def land(self, t: float, q_root: np.ndarray) -> None:
        """A successful landing before the CoM reached the plane (a reach over the bar onto the
        mat): take the crossing here, at the closest approach (ours; the episode ends at the
        landing, so the CoM never gets to cross)."""
        if not self.crossed:
            self.crossed, self.time = True, float(t)
            self.q_root = rot.quat_normalize(np.asarray(q_root, dtype=float))
            self.at_landing = True

    def update_many(self, times: np.ndarray, signed_distances: np.ndarray, q_roots: np.ndarray) -> bool:
        """``update`` for each row, in order, in one call: ``times`` ``(k,)``, ``signed_distances``
        ``(k,)``, ``q_roots`` ``(k, 4)``. Equivalent to the loop, but only the rows around the first
        crossing are looked at one by one. True when the crossing was found in these rows; its row
        is then ``hit_index``."""
        k = len(times)
        if k == 0:
            return False
        if self.crossed:
            self._prev = (float(times[-1]), float(signed_distances[-1]), np.asarray(q_roots[-1], dtype=float).copy())
            return False
        d = np.asarray(signed_distances, dtype=float)
        if d.max() < 0.0:  # all before the plane (the common case; NaN takes the general path)
            self._prev = (float(times[-1]), float(d[-1]), np.asarray(q_roots[-1], dtype=float).copy())
            return False
        before = np.concatenate([[self._prev[1] if self._prev is not None else np.nan], d[:-1]])
        hits = np.flatnonzero((before < 0.0) & (d >= 0.0))
        if len(hits) == 0:
            self._prev = (float(times[-1]), float(d[-1]), np.asarray(q_roots[-1], dtype=float).copy())
            return False
        i = int(hits[0])
        self.hit_index = i
        if i > 0:
            self._prev = (float(times[i - 1]), float(d[i - 1]), np.asarray(q_roots[i - 1], dtype=float).copy())
        self.update(float(times[i]), float(d[i]), q_roots[i])
        self._prev = (float(times[-1]), float(d[-1]), np.asarray(q_roots[-1], dtype=float).copy())
        return True

    def stage1(self) -> float:
        """Stage-1 feature (angle to up), NaN before the crossing."""
        return up_angle(self.q_root) if self.q_root is not None else math.nan

    def stage2(self, suite_rotation: np.ndarray) -> np.ndarray:
        """Stage-2 feature ``(4,)`` (root orientation in the suite frame), NaN before the crossing."""
        if self.q_root is None:
            return np.full(4, np.nan)
        return suite_orientation(self.q_root, suite_rotation)
