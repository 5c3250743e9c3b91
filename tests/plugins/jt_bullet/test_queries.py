"""``jt_bullet.queries``: rays ignore the character's own bodies; heightfields are where they say."""

from __future__ import annotations

import numpy as np
import pytest

from jt_bullet.simulator import BulletSimulator


@pytest.fixture
def lying():
    """A humanoid lying on its back on flat ground (the get-up clip's first frame)."""
    from jt_tasks.getup.initial import clip_pose

    s = BulletSimulator({"sim": {"name": "bullet"}, "character": {"name": "humanoid"}, "spd": {"name": "df"}})
    q, qd = clip_pose("getup_faceup", False, 0)
    s.reset(q, qd)
    yield s
    s.close()


def grid_under(sim: BulletSimulator, n: int = 9, half: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """Vertical rays ``(n * n, 3)`` from 2 m above to 2 m below the ground, over the hips."""
    hips = 0.5 * (sim.link_pose(3)[0] + sim.link_pose(9)[0])
    g = np.linspace(-half, half, n)
    gx, gz = np.meshgrid(g, g, indexing="ij")
    starts = np.stack([hips[0] + gx.ravel(), np.full(n * n, 2.0), hips[2] + gz.ravel()], axis=1)
    ends = starts.copy()
    ends[:, 1] = -2.0
    return starts, ends


def test_rays_through_a_lying_character_hit_the_ground(lying):
    import pybullet as pb

    starts, ends = grid_under(lying)
    first = pb.rayTestBatch(starts.tolist(), ends.tolist(), physicsClientId=lying.client)
    through = [i for i, h in enumerate(first) if h[0] == lying.body_id]
    assert len(through) >= 10  # the grid really crosses the body
    hits = lying.ray(starts, ends)
    assert np.isfinite(hits).all()
    np.testing.assert_allclose(hits[:, 1], 0.0, atol=1e-6)  # the ground plane, not the body
    np.testing.assert_allclose(hits[:, [0, 2]], starts[:, [0, 2]], atol=1e-6)


def test_masked_ground_rays_have_the_bits_of_the_all_hits_path(lying):
    """The one-batch masked cast (static scene, ground plane) gives the points the general path
    (one cast, then every hit along the rays through the body) gives, bit for bit."""
    starts, ends = grid_under(lying, n=13, half=0.7)
    assert lying._static_planes() == frozenset([lying.ground])
    np.testing.assert_array_equal(lying.ray(starts, ends), lying._rays_general(starts, ends))


def test_rays_onto_a_box_under_the_body_take_the_general_path(lying):
    """With a box under the hips the rays that end on it are answered by the general path (the
    same bits as it), the rest by the masked cast; a moving body switches the mask off."""
    hip = lying.link_pose(3)[0]
    box = lying.add_box((0.15, 0.05, 0.15), (float(hip[0]), -0.02, float(hip[2])))
    try:
        starts, ends = grid_under(lying, n=9, half=0.4)
        hits = lying.ray(starts, ends)
        np.testing.assert_array_equal(hits, lying._rays_general(starts, ends))
        assert (np.abs(hits[:, 1] - 0.03) < 1e-6).sum() >= 4  # some rays really end on the box top
        assert lying._static_planes() is not None
    finally:
        lying.remove(box)
    import pybullet as pb

    ball = pb.createMultiBody(1.0, pb.createCollisionShape(pb.GEOM_SPHERE, radius=0.1, physicsClientId=lying.client),
                              basePosition=[50.0, 1.0, 50.0], physicsClientId=lying.client)
    try:
        assert lying._static_planes() is None
    finally:
        pb.removeBody(ball, physicsClientId=lying.client)


def test_ray_that_misses_everything_is_nan(lying):
    hits = lying.ray(np.array([[0.0, 5.0, 0.0], [0.0, 5.0, 0.0]]), np.array([[0.0, 3.0, 0.0], [0.0, -1.0, 0.0]]))
    assert np.isnan(hits[0]).all()
    assert hits[1, 1] == pytest.approx(0.0, abs=1e-6)


def test_rays_through_the_character_find_a_heightfield_under_it(lying):
    hip = lying.link_pose(3)[0]
    heights = np.full((21, 21), 0.3)
    heights[10:, :] = 0.5  # a step: rows from the centre on (x >= the hip's) are 0.2 m higher
    body = lying.add_heightfield(heights, 0.2, origin=(float(hip[0]), 0.0, float(hip[2])))
    try:
        starts, ends = grid_under(lying, n=5, half=0.3)
        starts[:, 1] = 3.0
        hits = lying.ray(starts, ends)
        assert np.isfinite(hits).all()
        dx = starts[:, 0] - float(hip[0])
        np.testing.assert_allclose(hits[dx < -0.25, 1], 0.3, atol=1e-4)
        np.testing.assert_allclose(hits[dx > 0.1, 1], 0.5, atol=1e-4)
    finally:
        lying.remove(body)


def _plateau_sim() -> tuple[BulletSimulator, int]:
    """A humanoid lying on a 0.4 m plateau heightfield with its edge in the default camera's view."""
    from jt_tasks.getup.initial import clip_pose

    s = BulletSimulator({"sim": {"name": "bullet"}, "character": {"name": "humanoid"}, "spd": {"name": "df"}})
    q, qd = clip_pose("getup_faceup", False, 0)
    q = np.array(q, dtype=float)
    q[1] += 0.4
    s.reset(q, qd)
    heights = np.full((41, 41), 0.4)
    heights[:, :5] = 0.0
    return s, s.add_heightfield(heights, 0.1, origin=(0.0, 0.0, 0.0))


def test_a_heightfield_is_drawn_as_before_by_a_twin_made_at_the_first_render():
    """The physics body carries no converted visual (that costs ~0.9 kB per height sample in every
    env); the first render adds a collision-free twin, and the picture is the one of a heightfield
    body that converts its own visual."""
    import pybullet as pb

    s, body = _plateau_sim()
    try:
        kw = {"physicsClientId": s.client}
        (vis,) = pb.getVisualShapeData(body, **kw)
        assert vis[2] == pb.GEOM_SPHERE  # the speck, not the terrain
        n_before = pb.getNumBodies(**kw)
        img = s.render(96, 72)
        s.render(96, 72)
        assert pb.getNumBodies(**kw) == n_before + 1  # one twin, made once
        entry = s.terrain_visuals[body]
        assert entry["twin"] is not None
        # the old way: the physics body converts its own visual (here a second body, the twin hidden)
        pb.removeBody(entry["twin"], **kw)
        entry["twin"] = pb.createMultiBody(0.0, entry["shape"], -1, entry["position"], entry["orientation"], **kw)
        pb.setCollisionFilterGroupMask(entry["twin"], -1, 0, 0, **kw)
        assert np.abs(s.render(96, 72).astype(int) - img.astype(int)).max() <= 2
        flat = BulletSimulator({"sim": {"name": "bullet"}, "character": {"name": "humanoid"}, "spd": {"name": "df"}})
        try:
            flat.reset(*s.state())
            assert np.abs(flat.render(96, 72).astype(int) - img.astype(int)).max() > 50  # the terrain shows
        finally:
            flat.close()
    finally:
        s.close()


def test_the_drawn_twin_takes_no_contacts_and_no_rays():
    """After a render, the character still rests on the physics heightfield alone, rays still stop
    on it, and removing the heightfield removes its twin."""
    import pybullet as pb

    s, body = _plateau_sim()
    try:
        kw = {"physicsClientId": s.client}
        s.render(64, 48)
        twin = s.terrain_visuals[body]["twin"]
        for _ in range(60):
            pb.stepSimulation(**kw)
        touching = {c[2] for c in pb.getContactPoints(bodyA=s.body_id, **kw)}
        assert body in touching and twin not in touching
        hit = pb.rayTest([1.5, 3.0, 1.5], [1.5, -1.0, 1.5], **kw)[0]
        assert hit[0] == body and hit[3][1] == pytest.approx(0.4, abs=1e-4)
        n = pb.getNumBodies(**kw)
        s.remove(body)
        assert pb.getNumBodies(**kw) == n - 2 and not s.terrain_visuals
    finally:
        s.close()
