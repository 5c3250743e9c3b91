"""Style features of a simulated state on any terrain (``003`` §3.1, §3.3.1, §4.2, Fig. 4).

* ``side`` = unit vector from the left to the right hip joint ("oriented with the hips and
  directed to the character's right side", §3.1);
* ``front`` = normalize((neck − hip midpoint) × side) (Fig. 4);
* ``h`` = height of the neck base above the *mean* terrain height of the 5 × 5 height map (§4.2:
  "the vertical distance from the base of the neck to the average terrain height computed from the
  height map"), not the ground right under the neck;
* ``θx`` = ∠(side, up), ``θz`` = ∠(front, up), radians in [0, π] (the paper's ``w_θy`` is θz).

Standing upright gives about (1.3 m, π/2, π/2) on jt's humanoid; lying supine θz ≈ 0, prone ≈ π.

The heading frame (for the observation and the height map) must stay defined when the character
lies down, where the root's x axis points up: its forward direction is ``up × side`` (horizontal
by construction; the facing direction when standing, along the body's long axis when lying
prone or supine), falling back to the horizontal projection of ``neck − hips`` when the side vector is near
vertical (lying on the side), and to world +x when both vanish (ours; 003 does not say).
Everything here is y-up (the humanoid's world).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

UP = np.array([0.0, 1.0, 0.0])
#: the humanoid's links whose joint origins give the style features (names; ``torso_links``)
NECK, RIGHT_HIP, LEFT_HIP = "neck", "right_hip", "left_hip"
HEAD = "neck"  #: the neck link carries the head sphere
#: below this horizontal norm of ``up × side`` the heading falls back to the torso axis (ours)
SIDE_FALLBACK = 0.3


def angle_to_up(v: np.ndarray) -> float:
    """∠(v, up) in [0, π] (atan2 form: exact near 0 and π)."""
    v = np.asarray(v, dtype=np.float64)
    return float(math.atan2(np.linalg.norm(np.cross(v, UP)), float(v @ UP)))


def torso_vectors(neck: np.ndarray, r_hip: np.ndarray, l_hip: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(side, front)`` unit vectors (``003`` Fig. 4) from the neck base and hip joint origins."""
    side = np.asarray(r_hip, float) - np.asarray(l_hip, float)
    side = side / max(float(np.linalg.norm(side)), 1e-12)
    front = np.cross(np.asarray(neck, float) - 0.5 * (np.asarray(r_hip, float) + np.asarray(l_hip, float)), side)
    return side, front / max(float(np.linalg.norm(front)), 1e-12)


def style_features(neck: np.ndarray, r_hip: np.ndarray, l_hip: np.ndarray, ground_mean: float) -> np.ndarray:
    """``(h, θx, θz)`` ``(3,)``: neck height above ``ground_mean`` and the two torso angles."""
    side, front = torso_vectors(neck, r_hip, l_hip)
    return np.array([float(neck[1]) - float(ground_mean), angle_to_up(side), angle_to_up(front)])


def heading_yaw(neck: np.ndarray, r_hip: np.ndarray, l_hip: np.ndarray) -> float:
    """Yaw (rad about +y) of the heading frame: +x turned by it is the heading direction."""
    side, _ = torso_vectors(neck, r_hip, l_hip)
    fwd = np.cross(UP, side)  # horizontal; the facing direction when standing
    n = float(np.linalg.norm(fwd))
    if n < SIDE_FALLBACK:  # on the side: the torso's long axis, projected
        axis = np.asarray(neck, float) - 0.5 * (np.asarray(r_hip, float) + np.asarray(l_hip, float))
        axis[1] = 0.0
        if float(np.linalg.norm(axis)) > 1e-6:
            fwd = axis
        elif n < 1e-9:
            fwd = np.array([1.0, 0.0, 0.0])
    return float(math.atan2(-fwd[2], fwd[0]))


def heading_rotation(yaw: float) -> np.ndarray:
    """World → heading-frame rotation matrix ``(3, 3)`` (inverse of the yaw about +y)."""
    c, s = math.cos(yaw), math.sin(yaw)
    # R_y(yaw) maps +x to (c, 0, -s); its transpose maps world into the heading frame
    return np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])


def heightmap_points(centre: np.ndarray, yaw: float, n: int = 5, spacing: float = 0.25) -> np.ndarray:
    """Ground-plane sample points ``(n * n, 3)`` of the height map: an ``n × n`` grid of ``spacing``
    metres centred on ``centre`` (x, z), aligned with the heading frame (``003`` §3.2: 1 m × 1 m,
    25 cm); y is left at ``centre``'s."""
    offs = (np.arange(n) - (n - 1) / 2.0) * spacing
    gx, gz = np.meshgrid(offs, offs, indexing="ij")
    local = np.stack([gx.ravel(), np.zeros(n * n), gz.ravel()], axis=1)
    world = local @ heading_rotation(yaw)  # local (row) → world: R_y(yaw) = heading_rotation(yaw).T
    return world + np.array([centre[0], centre[1], centre[2]])


def torso_links(sim: Any) -> tuple[int, int, int]:
    """The simulator's link indices of ``NECK``, ``RIGHT_HIP``, ``LEFT_HIP`` (for ``measure``)."""
    return sim.link_index(NECK), sim.link_index(RIGHT_HIP), sim.link_index(LEFT_HIP)


def measure(sim: Any, n: int = 5, spacing: float = 0.25, ray_span: float = 5.0,
            links: Any = None) -> dict[str, Any]:
    """Style features, heading and height map of the simulator's current state.

    Args:
        sim: the simulator, holding the state.
        n, spacing: the height map's grid (``heightmap_points``).
        ray_span: m above and below the hips that its rays span.
        links: ``torso_links(sim)``, resolved once by a caller that measures every step; None:
            resolved here.

    Returns:
        ``features`` (h, θx, θz) ``(3,)``, ``yaw``, ``heightmap`` ``(n * n,)`` (hip height above
        the ground at each grid point, ``003`` §3.2), ``ground`` ``(n * n,)`` terrain heights,
        ``neck``, ``r_hip``, ``l_hip`` ``(3,)``.
    """
    from jt_tasks.getup import kernels

    neck, r_hip, l_hip = sim.link_poses(torso_links(sim) if links is None else links)[0]
    starts, ends, torso = np.empty((n * n, 3)), np.empty((n * n, 3)), np.empty(6)
    # heading_yaw, heightmap_points and torso_vectors in one compiled pass (the same formulas)
    yaw = kernels.frame(neck, r_hip, l_hip, n, spacing, ray_span, SIDE_FALLBACK, starts, ends, torso)
    ground = ground_heights(sim, starts, ends)
    feats = np.array([float(neck[1]) - float(np.mean(ground)), kernels.angle_to_up(*torso[:3].tolist()),
                      kernels.angle_to_up(*torso[3:].tolist())])
    return {"features": feats, "yaw": yaw, "heightmap": 0.5 * (r_hip[1] + l_hip[1]) - ground, "ground": ground,
            "neck": neck, "r_hip": r_hip, "l_hip": l_hip}


def ground_heights(sim: Any, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Terrain heights ``(n,)`` under vertical rays ``starts -> ends`` (``sim.ray`` ignores the
    character, so rays through a lying body reach the ground under it); a ray that misses
    everything (off the world's edge) takes the mean of the others, or the rays' lowest end (ours).
    """
    hits = np.asarray(sim.ray(starts, ends), float)[:, 1]
    bad = ~np.isfinite(hits)
    if bad.all():
        return np.full(len(hits), float(np.min(ends[:, 1])))
    hits[bad] = float(np.mean(hits[~bad]))
    return hits
