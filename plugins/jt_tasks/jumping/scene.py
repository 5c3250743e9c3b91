"""The jumping suites (``000`` §6.1): a bar wall or an obstacle box, and a rigid landing mat.

Built as static boxes through the simulator interface (``Simulator.add_box``), in the take-off *facing frame* (the character
at the origin heading +x, y up, +z its right; ``jt_tasks.takeoff.state``).

High jump: "The crossbar is modeled as a rigid wall vertically extending from the ground to the
target height [...] We model the landing area as a rigid block" (``000`` §6.1). The approach
angle ``alpha`` orients the wall by the line ``x sin(alpha) - z cos(alpha) = 0`` of the facing
frame (``000`` App. A); we shift that line by ``distance`` along its normal
``n = (sin alpha, 0, -cos alpha)`` so the take-off point lies ``distance`` before the bar plane
(our reading: the line through the take-off point itself would put the bar under the jumper).
Along the bar, the wall and the mat are centred where the take-off velocity's horizontal line
crosses the bar plane (``centre_along``; ours): a run-up at a shallow angle crosses 1.5-2 m along
the bar, which a wall centred on the foot of the perpendicular would leave near its end.

Obstacle / long jump: a box of ``height`` (50 cm, ``000`` §6.1) and variable ``width`` along the
run direction (+x), ``distance`` ahead of the take-off point; the mat begins behind it. A long
jump is an obstacle of height 0: no box, the mat lies ``distance + width`` ahead.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np


@dataclasses.dataclass
class SuiteSpec:
    """Geometry of a suite (all lengths in m)."""

    kind: str = "highjump"  # highjump | obstacle
    alpha: float = 0.0  # approach angle (rad), high jump only (000 App. A)
    distance: float = 0.9  # take-off point to the bar plane / obstacle's near face (ours)
    bar_height: float = 0.5  # wall height = bar height (000 §6.1; the curriculum sets it)
    obstacle_width: float = 0.05  # obstacle extent along the run (000 Table 1: 5 ... 250 cm)
    obstacle_height: float = 0.5  # obstacle height (000 §6.1: 50 cm; 0 = long jump)
    wall_thickness: float = 0.05  # ours
    wall_length: float = 4.0  # ours (an Olympic crossbar is ~4 m)
    mat_height: float = 0.3  # ours: the paper gives no size for its rigid landing block
    mat_depth: float = 3.0  # ours: extent behind the bar / obstacle
    mat_length: float = 5.0  # ours: extent along the bar
    gap: float = 0.01  # between the wall/obstacle and the mat (ours)
    centre_along: float = 0.0  # m along the bar of the wall's and mat's centres (ours; Suite.crossing_along)


def _quat_from_columns(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> list[float]:
    from toolkit.motion.rotations import matrix_to_quat

    return [float(v) for v in matrix_to_quat(np.stack([a, b, c], axis=1))]


class Suite:
    """The bodies of a suite in a simulator's scene, and its geometry.

    Attributes:
        normal: horizontal unit normal of the bar / obstacle plane ``(3,)``, pointing away from
            the take-off side.
        along: horizontal unit vector along the bar ``(3,)`` (``normal × up``).
        plane: signed offset of the feature plane (bar plane, or the obstacle's centre plane):
            a point ``p`` is past it when ``normal · p > plane``.
        barrier_id: scene handle of the wall / obstacle (-1: none).
        mat_id: scene handle of the landing mat.

    Args:
        sim: the simulator (``toolkit.interfaces.Simulator``) the suite stands in.
        spec: its geometry.
    """

    def __init__(self, sim: Any, spec: SuiteSpec) -> None:
        self.sim = sim
        self.spec = dataclasses.replace(spec)
        self.barrier_id = -1
        self.mat_id = -1
        self.build(spec)

    # ------------------------------------------------------------------ geometry
    def _frame(self, spec: SuiteSpec) -> None:
        a = spec.alpha if spec.kind == "highjump" else 0.0
        self.normal = np.array([math.sin(a), 0.0, -math.cos(a)]) if spec.kind == "highjump" \
            else np.array([1.0, 0.0, 0.0])
        self.up = np.array([0.0, 1.0, 0.0])
        self.along = np.cross(self.normal, self.up)
        self._rotation = np.stack([self.normal, self.up, self.along], axis=1)
        self._rotation.flags.writeable = False  # shared by every caller of rotation()
        if spec.kind == "highjump":
            self.near, self.far = spec.distance - spec.wall_thickness / 2, spec.distance + spec.wall_thickness / 2
            self.barrier_height = spec.bar_height
        else:
            self.near, self.far = spec.distance, spec.distance + spec.obstacle_width
            self.barrier_height = spec.obstacle_height
        self.plane = 0.5 * (self.near + self.far)

    def _box(self, centre_n: float, depth: float, height: float, length: float,
             rgba: tuple[float, ...]) -> int:
        half = [length / 2, height / 2, depth / 2]  # local x along the bar, y up, z along normal
        orn = _quat_from_columns(self.along, self.up, np.cross(self.along, self.up))
        pos = centre_n * self.normal + self.spec.centre_along * self.along + (height / 2) * self.up
        return self.sim.add_box(half, list(pos), orn, rgba, friction=0.9)

    def build(self, spec: SuiteSpec) -> None:
        """(Re)create the bodies for ``spec``."""
        for b in (self.barrier_id, self.mat_id):
            if b >= 0:
                self.sim.remove(b)
        self.spec = dataclasses.replace(spec)
        self._frame(spec)
        self.barrier_id = -1
        if self.barrier_height > 1e-6:
            length = spec.wall_length if spec.kind == "highjump" else spec.mat_length
            self.barrier_id = self._box(self.plane, self.far - self.near, self.barrier_height,
                                        length, (0.8, 0.2, 0.2, 1.0))
        m0 = self.far + spec.gap
        self.mat_id = self._box(m0 + spec.mat_depth / 2, spec.mat_depth, spec.mat_height,
                                spec.mat_length, (0.2, 0.3, 0.8, 1.0))

    def update(self, **changes: Any) -> bool:
        """Rebuild when a geometry value changed (e.g. the curriculum's bar height); True if so."""
        new = dataclasses.replace(self.spec, **changes)
        if new == self.spec:
            return False
        self.build(new)
        return True

    #: largest |centre_along| (m): a take-off this oblique cannot reach the plane in flight anyway
    MAX_CENTRE_ALONG = 5.0

    def crossing_along(self, velocity: np.ndarray) -> float:
        """Where along the bar the straight horizontal line of ``velocity`` ``(3,)`` from the take-off
        point crosses the feature plane (m, clipped to ``MAX_CENTRE_ALONG``); 0 when it never does."""
        v = np.asarray(velocity, dtype=float)
        towards = float(v @ self.normal)
        if towards <= 1e-3:
            return 0.0
        s = self.plane * float(v @ self.along) / towards
        return float(np.clip(s, -self.MAX_CENTRE_ALONG, self.MAX_CENTRE_ALONG))

    def beside(self, points: np.ndarray) -> np.ndarray:
        """Whether ``points`` ``(..., 3)`` lie beyond the ends of the wall / obstacle ``(...)``."""
        length = self.spec.wall_length if self.spec.kind == "highjump" else self.spec.mat_length
        return np.abs(self.along_offset(points)) > length / 2

    def along_offset(self, points: np.ndarray) -> np.ndarray:
        """Position of ``points`` ``(..., 3)`` along the bar, from the wall's centre ``(...)``."""
        return np.asarray(points) @ self.along - self.spec.centre_along

    # ------------------------------------------------------------------ queries
    def past(self, points: np.ndarray) -> np.ndarray:
        """Signed distance of ``points`` ``(..., 3)`` past the feature plane ``(...)``."""
        return np.asarray(points) @ self.normal - self.plane

    def rotation(self) -> np.ndarray:
        """Suite frame axes as columns ``(3, 3)`` (right-handed: normal × up = along), read-only:
        made once per frame (the observation reads it every control step)."""
        return self._rotation
