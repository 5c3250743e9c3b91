"""The get-up terrain: one world of four regions, flat → easy → medium → hard (``003`` §3.2, §5.4, Fig. 3).

``003`` §5.4: "the same terrain is used for all experiments, but it is divided into four regions
(flat, easy, medium, and hard difficulties)"; §3.2: "rough terrain variations are created by
perturbing the height of 1.0 m × 1.0 m tiles of a flat terrain"; Fig. 3: each harder region has
rough and sloped parts; §6.5: the steepest slope is 30°. The amplitudes are not given; ours:

* region ``k`` is a ``size`` × ``size`` square centred at ``(k · size, ·, 0)`` (x along the regions,
  y up); region 0 (flat) is the simulator's ground plane at the origin, where the clips' poses lie;
* regions ``k ≥ 1`` are static boxes (``sim.add_boxes``): the half ``z < 0``
  **rough**, 1 m tiles with heights uniform in ``[0, roughness[k]]`` (seeded), one flat-topped box
  each (a step at every tile edge); the half ``z ≥ 0`` **sloped**, a triangle wave along x of
  slope ``slope_deg[k]`` and period ``slope_period`` (ridges and valleys parallel to z), one tilted
  box per face. The boxes are ``heights_at`` exactly. (Until December 2026 this was a 0.125 m
  heightfield, which smoothed each tile edge into a ramp and cost ~9 MB per environment in
  PyBullet, 140 MB of a 16-env rollout worker; 108 boxes cost ~0.1 MB.)
* start locations are drawn uniformly in a region, ``margin`` m from its borders (steps between
  regions and halves are never under a start).

Everything is a function of the spec and its ``seed``: the same seed gives the same heights.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Optional

import numpy as np

REGIONS = ("flat", "easy", "medium", "hard")  #: 003 §5.4, Table 1's columns


@dataclasses.dataclass
class TerrainSpec:
    """The terrain world (every field picklable; ``GetupConfig.terrain`` documents each)."""

    size: float = 8.0
    tile: float = 1.0  # 003 §3.2: 1.0 m x 1.0 m tiles
    roughness: tuple = (0.0, 0.04, 0.08, 0.12)
    slope_deg: tuple = (0.0, 10.0, 20.0, 30.0)  # 003 §6.5: the steepest 30°
    slope_period: float = 4.0
    margin: float = 1.5
    seed: int = 0

    @classmethod
    def from_dict(cls, d: Optional[dict]) -> "TerrainSpec":
        d = dict(d or {})
        for k in ("roughness", "slope_deg"):
            if k in d:
                d[k] = tuple(float(v) for v in d[k])
        return cls(**{k: v for k, v in d.items() if k in {f.name for f in dataclasses.fields(cls)}})

    def to_dict(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in dataclasses.asdict(self).items()}

    @property
    def n_regions(self) -> int:
        return len(self.roughness)

    def check(self) -> list[str]:
        """Problems with the spec, one sentence each (empty: none)."""
        bad = []
        if len(self.roughness) != len(REGIONS) or len(self.slope_deg) != len(REGIONS):
            bad.append(f"roughness and slope_deg need {len(REGIONS)} values ({', '.join(REGIONS)})")
        if any(not (0.0 <= r < 1.0) for r in self.roughness):
            bad.append("roughness values must be in [0, 1) m")
        if any(not (0.0 <= s < 45.0) for s in self.slope_deg):  # the boxes' faces stay hole-free below 45°
            bad.append("slope_deg values must be in [0, 45)")
        if not (self.tile > 0 and self.slope_period > 0):
            bad.append("need tile > 0, slope_period > 0")
        if not (0.0 <= self.margin < self.size / 2):
            bad.append("need 0 <= margin < size / 2")
        return bad


def region_centre(spec: TerrainSpec, region: int) -> np.ndarray:
    """``(x, z)`` of region ``region``'s centre."""
    return np.array([region * spec.size, 0.0])


def region_of(spec: TerrainSpec, x: Any) -> np.ndarray:
    """Region index of world ``x`` (region 0 is everything left of the first heightfield)."""
    k = np.floor(np.asarray(x, float) / spec.size + 0.5).astype(int)
    return np.clip(k, 0, spec.n_regions - 1)


def _tile_heights(spec: TerrainSpec) -> np.ndarray:
    """Seeded tile heights ``(n_regions, tiles, tiles)``: uniform in ``[0, roughness[k]]``."""
    n = int(math.ceil(spec.size / spec.tile)) + 1
    rng = np.random.default_rng(int(spec.seed))
    u = rng.random((spec.n_regions, n, n))
    return u * np.asarray(spec.roughness, float)[:, None, None]


def heights_at(spec: TerrainSpec, x: Any, z: Any, tiles: Optional[np.ndarray] = None) -> np.ndarray:
    """The designed terrain height (m) at world points ``(x, z)`` (same shapes): 0 on region 0 and
    outside the world, tile heights on rough halves, the triangle wave on sloped halves. The
    terrain's boxes (``boxes``) are this surface exactly."""
    x, z = np.broadcast_arrays(np.asarray(x, float), np.asarray(z, float))
    tiles = _tile_heights(spec) if tiles is None else tiles
    k = region_of(spec, x)
    lx = x - k * spec.size + spec.size / 2  # region-local, in [0, size)
    lz = z + spec.size / 2
    inside = (k >= 1) & (lz >= 0) & (lz <= spec.size) & (x >= spec.size / 2) & \
        (x <= (spec.n_regions - 0.5) * spec.size)
    ix = np.clip((lx // spec.tile).astype(int), 0, tiles.shape[1] - 1)
    iz = np.clip((lz // spec.tile).astype(int), 0, tiles.shape[2] - 1)
    rough = tiles[k, ix, iz]
    half = spec.slope_period / 2
    tri = half - np.abs(np.mod(lx, spec.slope_period) - half)  # 0 at valleys, half at ridges
    slope = np.tan(np.radians(np.asarray(spec.slope_deg, float)))[k] * tri
    return np.where(inside, np.where(z < 0.0, rough, slope), 0.0)


DEPTH = 0.5  #: how far every terrain box reaches below the ground plane (m)


def boxes(spec: TerrainSpec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The terrain of regions ``1..n−1`` as boxes: half extents ``(n, 3)``, centres ``(n, 3)``,
    orientations ``(n, 4)`` (x, y, z, w; y up). Rough halves: one box per tile, its top at the
    tile's height; sloped halves: one box per face of the triangle wave, turned about z, its top
    face on the wave. Every box reaches ``DEPTH`` below the ground plane."""
    tiles = _tile_heights(spec)
    half_ext, centres, orns = [], [], []
    half = spec.size / 2
    for k in range(1, spec.n_regions):
        x0 = k * spec.size - half  # the region's left edge
        edges_x = np.minimum(np.arange(0.0, spec.size + spec.tile, spec.tile), spec.size)
        edges_z = np.minimum(np.arange(0.0, half + spec.tile, spec.tile), half)
        for ix in range(len(edges_x) - 1):
            for iz in range(len(edges_z) - 1):
                a, b, c, d = edges_x[ix], edges_x[ix + 1], edges_z[iz], edges_z[iz + 1]
                if b <= a or d <= c:
                    continue
                h = float(tiles[k, ix, iz])
                half_ext.append([(b - a) / 2, (h + DEPTH) / 2, (d - c) / 2])
                centres.append([x0 + (a + b) / 2, (h - DEPTH) / 2, -half + (c + d) / 2])
                orns.append([0.0, 0.0, 0.0, 1.0])
        rise, p2 = math.tan(math.radians(float(spec.slope_deg[k]))), spec.slope_period / 2
        kinks = np.unique(np.minimum(np.arange(0.0, spec.size + spec.slope_period / 2, spec.slope_period / 2), spec.size))
        for a, b in zip(kinks[:-1], kinks[1:]):
            ya, yb = (rise * (p2 - abs(math.fmod(v, 2 * p2) - p2)) for v in (a, b))  # as ``heights_at``
            length, angle = math.hypot(b - a, yb - ya), math.atan2(yb - ya, b - a)
            # thick enough that the box's lower face is under the ground plane below its high end:
            # the solid between the wave and the plane has no hollow (with slopes < 45°, ``check``)
            thick = max(ya, yb) * math.cos(angle) + DEPTH
            normal = np.array([-math.sin(angle), math.cos(angle)])  # (x, y) of the face's up normal
            mid = np.array([x0 + (a + b) / 2, (ya + yb) / 2]) - normal * (thick / 2)
            half_ext.append([length / 2, thick / 2, half / 2])
            centres.append([mid[0], mid[1], half / 2])
            orns.append([0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2)])
    return np.asarray(half_ext), np.asarray(centres), np.asarray(orns)


def add_terrain(sim: Any, spec: TerrainSpec, friction: float = 1.0) -> tuple[int, ...]:
    """Build the regions ``1..n−1`` on ``sim`` as boxes (``sim.add_boxes``); their handles.
    ``friction``: 003 §3.2, μ = 1.0."""
    half, centres, orns = boxes(spec)
    return tuple(int(b) for b in sim.add_boxes(half, centres, orns, colours(spec, centres, orns), friction=friction))


def colours(spec: TerrainSpec, centres: np.ndarray, orientations: np.ndarray) -> np.ndarray:
    """RGBA ``(n, 4)`` of the terrain boxes, for pictures: earth tones unlike the grey character,
    rough tiles in a checkerboard of two shades (their steps show), slope faces a third."""
    k = np.floor(centres[:, 0] / spec.tile) + np.floor(centres[:, 2] / spec.tile)
    tile = np.where((k % 2 == 0)[:, None], [0.55, 0.47, 0.36, 1.0], [0.47, 0.40, 0.30, 1.0])
    tilted = np.abs(orientations[:, 2]) > 1e-9
    return np.where(tilted[:, None], [0.42, 0.50, 0.33, 1.0], tile)


def sample_locations(spec: TerrainSpec, region: int, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` start locations ``(n, 2)`` (x, z), uniform in region ``region`` ``margin`` m inside its
    borders, and (regions ≥ 1) ``margin`` / 2 from the rough/sloped seam at z = 0."""
    c = region_centre(spec, region)
    half = spec.size / 2 - spec.margin
    x = c[0] + rng.uniform(-half, half, n)
    z = rng.uniform(-half, half, n)
    if region >= 1:  # keep off the seam between the rough and the sloped halves
        gap = spec.margin / 2
        z = np.where(z < 0, np.minimum(z, -gap), np.maximum(z, gap))
    return np.stack([x, z], axis=1)


def place_on_ground(sim: Any, q: np.ndarray, qd: np.ndarray, xz: Any, clearance: float = 0.005) -> np.ndarray:
    """``q`` moved to ``(x, z)`` = ``xz`` and raised so that every link's box is ``clearance`` above
    the terrain under its centre and four lower corners (rays through ``sim``, which is left in the
    placed state); the pose's orientation is kept."""
    q = np.array(q, dtype=np.float64)
    q[0], q[2] = float(xz[0]), float(xz[1])
    q[1] += 2.0  # well clear of any terrain while measuring
    sim.reset(q, np.asarray(qd, float))
    lows, starts = [], []
    for link in range(-1, int(sim.n_links)):
        lo, hi = sim.aabb(link)
        lows.append(float(lo[1]))
        for fx, fz in ((0.5, 0.5), (0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)):
            starts.append([lo[0] + fx * (hi[0] - lo[0]), 50.0, lo[2] + fz * (hi[2] - lo[2])])
    starts = np.asarray(starts)
    ends = starts.copy()
    ends[:, 1] = -50.0
    ground = sim.ray(starts, ends)[:, 1].reshape(len(lows), -1)
    ground = np.where(np.isfinite(ground), ground, 0.0).max(axis=1)
    q[1] += float(np.max(ground + clearance - np.asarray(lows)))
    sim.reset(q, np.asarray(qd, float))
    return q


#: (joint, foot link, its parent link) of the humanoid, by name (``Simulator.link_index``)
FEET = (("right_ankle", "right_ankle", "right_knee"), ("left_ankle", "left_ankle", "left_knee"))


def ground_normal(sim: Any, x: float, z: float, d: float = 0.08) -> np.ndarray:
    """Unit normal ``(3,)`` of the ground around ``(x, z)`` from three vertical rays ``d`` m apart."""
    pts = np.array([[x, 50.0, z], [x + d, 50.0, z], [x, 50.0, z + d]])
    ends = pts.copy()
    ends[:, 1] = -50.0
    hit = sim.ray(pts, ends)
    if not np.isfinite(hit).all():
        return np.array([0.0, 1.0, 0.0])
    n = np.cross(hit[2] - hit[0], hit[1] - hit[0])
    return n / max(float(np.linalg.norm(n)), 1e-12) * (1.0 if n[1] >= 0 else -1.0)


def orient_feet(sim: Any, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """A standing pose ``q`` (``sim`` holding it) with each foot turned so that its sole lies in the
    local terrain slope (003 §5.2: "the feet of the character are re-oriented to match the local
    terrain slope"): the ankle rotation that tilts the foot's up axis onto the ground normal under it
    (the smallest such turn); ``sim`` is left holding the new pose, not yet re-placed."""
    from toolkit.motion import rotations as rot
    from toolkit.motion.skeletons import HUMANOID

    q = np.array(q, dtype=np.float64)
    up = np.array([0.0, 1.0, 0.0])
    for joint, link, parent in FEET:
        pos, foot = sim.link_pose(sim.link_index(link))
        _, par = sim.link_pose(sim.link_index(parent))
        n = ground_normal(sim, float(pos[0]), float(pos[2]))
        a = rot.quat_rotate(foot, up)  # the sole's normal now
        axis = np.cross(a, n)
        s, c = float(np.linalg.norm(axis)), float(a @ n)
        if s < 1e-9:
            continue
        turn = rot.quat_from_axis_angle(axis / s, math.atan2(s, c))
        local = rot.quat_multiply(rot.quat_conjugate(par), rot.quat_multiply(turn, foot))
        sl = HUMANOID.q_slices[joint]
        q[7 + sl.start:7 + sl.stop] = rot.quat_normalize(local)
    sim.reset(q, np.asarray(qd, float))
    return q
