"""The thesis characters: DoF layout, gains and limits, y-up placement, generated URDFs."""

from __future__ import annotations

import numpy as np
import pytest

EXPECTED = {  # name: (n_dof floating, movable joints, depth d)    001 Table 2.1 for n, d
    "humanoid": (34, 12, 13),
    "laikago": (18, 12, 9),
    "atlas": (36, 30, 16),
    "snake36": (36, 10, 36),
    "snake72": (72, 22, 72),
    "snake195": (195, 63, 195),
}


@pytest.fixture(scope="module")
def client():
    import pybullet as pb

    c = pb.connect(pb.DIRECT)
    pb.setGravity(0, -9.8, 0, physicsClientId=c)
    yield c
    pb.disconnect(c)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_layout_gains_and_limits(client, name):
    from jt_bullet.characters import load

    n_dof, n_joints, depth = EXPECTED[name]
    ch = load(name, client)
    model = ch.model()
    assert (ch.n_dof, len(ch.joint_indices), model.depth) == (n_dof, n_joints, depth)
    assert model.n_v == ch.n_dof and model.n_q == ch.n_q == len(ch.q_init)
    for arr in (ch.kp, ch.kd, ch.torque_limit):
        assert arr.shape == (n_dof,)
        assert np.all(arr[:6] == 0.0)  # unactuated root
        assert np.all(arr[6:] > 0.0)
    assert not ch.fixed_base


def test_humanoid_joint_types_and_paper_gains(client):
    import pybullet as pb

    from jt_bullet.characters import humanoid

    ch = humanoid(client)
    names = [pb.getJointInfo(ch.body_id, j, physicsClientId=client)[1].decode()
             for j in ch.joint_indices]
    dofs = dict(zip(names, ch.joint_dofs))
    assert {n for n, k in dofs.items() if k == 1} == {"right_knee", "left_knee", "right_elbow",
                                                      "left_elbow"}
    assert sum(ch.joint_dofs) == 28
    expected = {"chest": (1000, 200), "neck": (100, 50), "right_hip": (500, 200),
                "right_knee": (500, 150), "right_ankle": (400, 90), "right_shoulder": (400, 100),
                "right_elbow": (300, 60)}
    k = 6
    for n, d in zip(names, ch.joint_dofs):
        base = n.replace("left_", "right_")
        kp, lim = expected[base]
        assert np.all(ch.kp[k:k + d] == kp) and np.all(ch.kd[k:k + d] == kp / 10)
        assert np.all(ch.torque_limit[k:k + d] == lim)
        k += d


@pytest.mark.parametrize("name", ["humanoid", "atlas", "laikago"])
def test_characters_stand_y_up(client, name):
    """Feet (lowest link) below the root, head/chest above it, along +y."""
    import pybullet as pb

    from jt_bullet.characters import load

    ch = load(name, client, base_position=(5.0, 1.0, 0.0))
    ys = [pb.getLinkState(ch.body_id, j, physicsClientId=client)[0][1]
          for j in range(pb.getNumJoints(ch.body_id, physicsClientId=client))]
    root_y = ch.q_init[1]
    assert min(ys) < root_y - 0.2
    if name != "laikago":
        assert max(ys) > root_y + 0.2


def test_fixed_base_variant_has_no_root_dofs(client):
    from jt_bullet.characters import load

    ch = load("atlas", client, fixed_base=True)
    assert ch.fixed_base and ch.n_dof == 30 and ch.model().floating is False


def test_generated_urdfs_are_cached_and_deterministic(tmp_path, monkeypatch):
    from jt_bullet import urdfgen

    monkeypatch.setenv("JT_CACHE_DIR", str(tmp_path))
    a = urdfgen.write_cached("snake36", urdfgen.snake_urdf(10))
    b = urdfgen.write_cached("snake36", urdfgen.snake_urdf(10))
    assert a == b and a.startswith(str(tmp_path))
    assert urdfgen.snake_urdf(10) == urdfgen.snake_urdf(10)
    assert urdfgen.atlas_urdf() == urdfgen.atlas_urdf()
    assert urdfgen.snake_urdf(10).count('type="spherical"') == 10
    assert urdfgen.atlas_urdf().count('type="revolute"') == 30


def test_unknown_character_is_one_clear_error(client):
    from jt_bullet.characters import load

    with pytest.raises(ValueError, match="unknown character 'dog'"):
        load("dog", client)


def test_characters_module_imports_nothing_heavy():
    import subprocess
    import sys

    code = ("import sys, jt_bullet.characters; "
            "assert not [m for m in ('pybullet', 'numba', 'torch') if m in sys.modules]")
    subprocess.run([sys.executable, "-c", code], check=True)
