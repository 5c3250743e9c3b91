"""``jt_bullet.planar``: the bullet simulator's planar world (reached through the registry), and
the one-line errors of ``BulletSimulator.load_character``."""

from __future__ import annotations

import numpy as np
import pytest

from toolkit import plugins
from toolkit.errors import JtError


@pytest.fixture()
def world():
    from jt_tasks.standing_jump.model import build_body, write_urdf

    body = build_body(80.0, 1.60)
    w = plugins.load("sim", "bullet").planar_world(write_urdf(body), sim_hz=600.0, friction=1.0)
    w.reset_joint(w.joint_names.index("root_z"), body.hip_height + 1e-4)
    yield w
    w.close()


def test_joint_reads_and_resets_round_trip(world):
    n = world.n_joints
    assert n == len(world.joint_names) == len(world.link_names) == 19
    assert world.joint_names[:3] == ["root_x", "root_z", "root_pitch"]
    q = np.linspace(-0.3, 0.3, n)
    qd = np.linspace(1.0, -1.0, n)
    world.reset_joints(q, qd)
    q2, qd2 = world.joint_states()
    np.testing.assert_allclose(q2, q, atol=1e-12)
    np.testing.assert_allclose(qd2, qd, atol=1e-12)
    world.reset_joints(q)  # velocities default to zero
    assert world.joint_states()[1] == [0.0] * n


def test_standing_on_the_ground_and_torques_move_it(world):
    world.step()
    contacts = world.ground_contacts()
    assert contacts and all(f >= 0.0 for _, f in contacts)
    feet = {world.link_names[k] for k, _ in contacts}
    assert feet <= {name for name in world.link_names if "foot" in name or "toe" in name}
    q0, _ = world.joint_states()
    tau = [0.0] * world.n_joints
    tau[world.joint_names.index("root_x")] = 200.0  # a push on the root's prismatic joint
    for _ in range(30):
        world.apply_torques(tau)
        world.step()
    assert world.joint_states()[0][0] > q0[0]


def test_gravity_model_and_render(world):
    model = world.model()
    assert model.n_v == world.n_joints and not model.floating
    world.set_gravity(0.0)
    world.reset_joint(world.joint_names.index("root_z"), 3.0)  # in the air, no gravity: stays
    _, z0 = world.joint_states()[0][:2]
    for _ in range(20):
        world.apply_torques([0.0] * world.n_joints)
        world.step()
    assert world.joint_states()[0][1] == pytest.approx(z0, abs=1e-9)
    img = world.render(40, 60, eye=[0.0, -4.2, 1.0], target=[0.0, 0.0, 1.0])
    assert img.shape == (60, 40, 3) and img.dtype == np.uint8 and img.std() > 0


def test_close_is_idempotent(world):
    world.close()
    world.close()
    assert world.client is None


def test_unknown_joint_gain_is_a_one_line_jt_error():
    import pybullet as pb

    sim = plugins.load("sim", "bullet")
    c = pb.connect(pb.DIRECT)
    try:
        with pytest.raises(JtError, match="no movable joint 'tail'; joints: .*neck") as err:
            sim.load_character({"name": "humanoid", "joint_kd": {"tail": 1.0}}, c)
        assert isinstance(err.value, KeyError) and "\n" not in str(err.value)
        assert not str(err.value).startswith("'")  # the message, not KeyError's quoted repr
    finally:
        pb.disconnect(c)
