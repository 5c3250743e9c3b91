"""``jt_bullet.queries``: rays ignore the character's own bodies."""

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
