"""The get-up terrain (003 §3.2, §5.4): real PyBullet boxes, seeded; the height map and h follow it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from getup_helpers import sim_groups
from jt_tasks.getup import terrain as T
from toolkit.errors import JtError


@pytest.fixture(scope="module")
def world():
    """A bullet simulator holding the default terrain."""
    from toolkit.policy.env import load_simulator

    sim = load_simulator(sim_groups())
    spec = T.TerrainSpec()
    T.add_terrain(sim, spec)
    yield sim, spec
    sim.close()


def down_rays(xz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    starts = np.stack([xz[:, 0], np.full(len(xz), 20.0), xz[:, 1]], axis=1)
    ends = starts.copy()
    ends[:, 1] = -1.0
    return starts, ends


def test_regions_are_rough_and_sloped_as_designed_and_seeded():
    spec = T.TerrainSpec()
    a, b = T.boxes(spec)[1], T.boxes(T.TerrainSpec())[1]
    np.testing.assert_array_equal(a, b)  # same seed, same heights
    assert not np.array_equal(a, T.boxes(T.TerrainSpec(seed=1))[1])
    assert len(a) == 3 * (8 * 4 + 4)  # 3 regions: 32 rough tiles, 4 slope faces each
    rng = np.random.default_rng(0)
    for region in range(1, 4):
        xz = T.sample_locations(spec, region, 400, rng)
        assert np.all(T.region_of(spec, xz[:, 0]) == region)
        h = T.heights_at(spec, xz[:, 0], xz[:, 1])
        rough, slope = h[xz[:, 1] < 0], h[xz[:, 1] > 0]
        assert 0.0 <= rough.min() and rough.max() <= spec.roughness[region] + 1e-12
        assert np.ptp(rough) > 0.5 * spec.roughness[region]  # really perturbed tiles
        top = math.tan(math.radians(spec.slope_deg[region])) * spec.slope_period / 2
        assert slope.max() <= top + 1e-12 and slope.max() > 0.5 * top
    flat = T.heights_at(spec, *T.sample_locations(spec, 0, 100, rng).T)
    assert np.all(flat == 0.0)


def test_terrain_in_pybullet_is_the_design(world):
    """Rays anywhere on the terrain (tile edges and ridges included) land on ``heights_at``."""
    sim, spec = world
    rng = np.random.default_rng(1)
    xs = rng.uniform(spec.size / 2, (spec.n_regions - 0.5) * spec.size, 3000)
    zs = rng.uniform(-spec.size / 2, spec.size / 2, 3000)
    hit = sim.ray(*down_rays(np.stack([xs, zs], axis=1)))[:, 1]
    np.testing.assert_allclose(hit, T.heights_at(spec, xs, zs), atol=1e-3)
    for region in range(1, 4):  # rough tiles away from their edges: the tops are exact
        cells = rng.integers(0, [8, 4], (200, 2))
        pts = [region * spec.size - spec.size / 2, -spec.size / 2] + (cells + rng.uniform(0.1, 0.9, (200, 2))) * spec.tile
        np.testing.assert_allclose(sim.ray(*down_rays(pts))[:, 1], T.heights_at(spec, pts[:, 0], pts[:, 1]), atol=1e-6)


def test_no_hollow_under_the_slopes(world):
    """Horizontal rays into the sloped half's outer side, under the wave, hit its side face at once:
    the tilted boxes leave no hollow a fallen character could slide into."""
    sim, spec = world
    for region in range(1, 4):
        x0 = region * spec.size - spec.size / 2
        xs = x0 + np.linspace(0.2, spec.size - 0.2, 25)
        ys = 0.9 * T.heights_at(spec, xs, np.full(25, 1.0))
        starts = np.stack([xs, ys, np.full(25, spec.size / 2 + 1.0)], axis=1)
        ends = starts.copy()
        ends[:, 2] = 0.5
        hit = sim.ray(starts, ends)
        np.testing.assert_allclose(hit[ys > 0.01, 2], spec.size / 2, atol=1e-3)


def test_hard_slope_is_30_degrees(world):
    sim, spec = world
    x0 = 3 * spec.size - spec.size / 2 + 0.5  # inside the first up-slope of the hard region
    hits = sim.ray(*down_rays(np.array([[x0, 2.0], [x0 + 1.0, 2.0]])))[:, 1]
    assert math.degrees(math.atan2(hits[1] - hits[0], 1.0)) == pytest.approx(30.0, abs=0.5)  # 003 §6.5


def test_height_map_and_h_follow_the_terrain(world):
    from jt_tasks.getup import features as F
    from jt_tasks.getup.initial import clip_pose

    sim, spec = world
    q, qd = clip_pose("getup_facedown", False, frame=-1)  # standing
    grounds = {}
    for region in (0, 3):
        xz = T.sample_locations(spec, region, 1, np.random.default_rng(5))[0]
        xz[1] = -abs(xz[1])  # the rough half
        T.place_on_ground(sim, q, qd, xz)
        m = F.measure(sim)
        pts = F.heightmap_points(0.5 * (m["r_hip"] + m["l_hip"]), m["yaw"])
        np.testing.assert_allclose(m["ground"], T.heights_at(spec, pts[:, 0], pts[:, 2]), atol=0.03)
        assert m["features"][0] == pytest.approx(m["neck"][1] - m["ground"].mean())
        grounds[region] = m["ground"]
    assert np.all(grounds[0] == pytest.approx(0.0, abs=1e-6))
    assert np.ptp(grounds[3]) > 0.02 and grounds[3].mean() > 0.01  # not flat under the character


def test_rag_doll_drops_land_on_the_terrain_at_seeded_locations():
    from jt_tasks.getup.ground import lowest_point
    from jt_tasks.getup.initial import fallen_states

    spec = T.TerrainSpec()
    kw = dict(styles=("prone",), settle_max=1.0, max_tries=1, terrain=spec.to_dict(), region=2)
    a = fallen_states(sim_groups(), 1, 7, **kw)
    b = fallen_states(sim_groups(), 1, 7, **kw)
    assert a[0]["q"] == b[0]["q"] and a[0]["region"] == 2
    x, z = a[0]["xz"]
    assert T.region_of(spec, x) == 2 and abs(a[0]["q"][0] - x) < 1.0 and abs(a[0]["q"][2] - z) < 1.0
    under = T.heights_at(spec, x, z)
    assert lowest_point(np.asarray(a[0]["q"])) < float(under) + 0.15  # lying on the terrain, not floating


def test_curriculum_level_bounds_the_regions_visited():
    from toolkit import plugins
    from toolkit.config import compose, validate

    cfg = validate(compose(["task=getup", "action=raw", "task.n_fallen=1", "task.settle_max=0.5"]))
    task = plugins.load("task", "getup")(cfg)
    assert task.train_regions() == [0, 1, 2, 3]
    env = task.make_env(None, seed=0)
    try:
        env.terrain_level = 1
        regions = {env.reset(seed=s)[1]["terrain_level"] for s in range(40)}
        assert regions == {0.0, 1.0}  # every unlocked region visited, nothing beyond (003 §5.4)
        _, info = env.reset(options={"region": 3, "kind": "standing"})
        assert info["terrain_level"] == 3.0 and T.region_of(T.TerrainSpec(), env.sim.state()[0][0]) == 3
        _, info = env.reset(options={"region": 2})
        assert info["start_kind"] in (1.0, 2.0)  # no clip poses on irregular ground (003 §5.2)
    finally:
        env.close()


@pytest.mark.parametrize("override, match", [
    ("task.eval_regions=[flat,steep]", "task.eval_regions"),
    ("task.eval_locations=0", "task.eval_locations"),
    ("task.terrain.roughness=[0,0.1]", "task.terrain"),
    ("task.train_regions=all", "task.train_regions"),
    ("task.terrain.slope_deg=[0,10,20,50]", r"slope_deg values must be in \[0, 45\)"),  # boxes: hole-free below 45°
    ("+task.terrain.cell=0.25", "task.terrain.cell=0.25: is not a terrain key .*boxes"),  # the former heightfield grid
    ("+task.terrain.sise=9", "task.terrain.sise=9: is not a terrain key; the keys: size, tile"),
])
def test_bad_terrain_input_is_one_line(override, match):
    from toolkit.config import compose, validate

    with pytest.raises(JtError, match=match) as e:
        validate(compose(["task=getup", "action=raw", override]))
    assert "\n" not in str(e.value)


def test_standing_starts_on_a_slope_get_their_feet_turned_to_it(world):
    from jt_tasks.getup.initial import clip_pose
    from toolkit.motion import rotations as rot

    sim, spec = world
    q, qd = clip_pose("getup_facedown", False, frame=-1)
    xz = np.array([3 * spec.size - spec.size / 2 + 1.0, 2.0])  # the middle of a 30° face

    def sole_angles() -> list[float]:
        out = []
        for _, link, _ in T.FEET:
            pos, foot = sim.link_pose(sim.link_index(link))
            a = rot.quat_rotate(foot, np.array([0.0, 1.0, 0.0]))
            out.append(math.degrees(math.acos(min(1.0, float(a @ T.ground_normal(sim, pos[0], pos[2]))))))
        return out

    q1 = T.place_on_ground(sim, q, qd, xz)
    assert min(sole_angles()) > 10.0  # a flat-ground stance on 30°
    q2 = T.orient_feet(sim, q1, qd)
    T.place_on_ground(sim, q2, qd, xz)
    assert max(sole_angles()) < 2.0  # 003 §5.2: feet re-oriented to the local slope
    np.testing.assert_array_equal(q2[7:20], q1[7:20])  # only the ankles changed (chest .. right knee)
