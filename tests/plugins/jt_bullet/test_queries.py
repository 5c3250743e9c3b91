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
