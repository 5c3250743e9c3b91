"""The planar humanoid: anthropometry, URDF, and planar kinematics against PyBullet."""

from __future__ import annotations

import numpy as np
import pytest

from jt_tasks.standing_jump import model
from jt_tasks.standing_jump.kinematics import PlanarKinematics


def test_body_matches_the_paper_and_de_leva():
    b = model.build_body()
    assert len(b.links) == 17  # 004 §3: "The model has 17 links"
    assert sum(link.mass for link in b.links) == pytest.approx(80.0)  # "weighs 80 kg"
    top = b.hip_height + sum(b.link(n).origin[2] for n in ("abdomen", "chest", "neck", "head")) + b.head_top[1]
    assert top == pytest.approx(1.60)  # "160 cm tall"
    # de Leva 1996: thigh 14.16 %, shank 4.33 %, foot 1.37 % of body mass
    assert b.link("thigh_l").mass == pytest.approx(0.1416 * 80)
    assert b.link("shank_r").mass == pytest.approx(0.0433 * 80)
    assert b.link("foot_l").mass == pytest.approx(0.0137 * 80)
    # left-right symmetric
    for a, c in (("thigh_l", "thigh_r"), ("upper_arm_l", "upper_arm_r"), ("foot_l", "foot_r")):
        assert b.link(a).mass == b.link(c).mass and b.link(a).com == b.link(c).com
    assert len(b.joint_names) == 16


def test_effort_weights_follow_table_1_normalised_to_n():
    b = model.build_body()
    w = model.effort_weights(b)
    assert sum(w.values()) == pytest.approx(16.0)  # "normalized so that sum w_i = n"
    assert w["hip_l"] / w["ankle_l"] == pytest.approx(2.5)  # Table 1: hips 2.5, ankles 1
    assert w["abs"] / w["elbow_r"] == pytest.approx(6.0)  # abs 3, elbows 0.5
    assert w["wrist_l"] / w["knee_r"] == pytest.approx(0.125)  # wrists 0.25, knees 2


def test_urdf_is_deterministic_and_content_addressed(tmp_path):
    b = model.build_body()
    assert model.urdf_text(b) == model.urdf_text(model.build_body())
    p1 = model.write_urdf(b, cache_dir=tmp_path)
    p2 = model.write_urdf(b, cache_dir=tmp_path)
    assert p1 == p2 and p1.read_text() == model.urdf_text(b)
    assert model.write_urdf(b, rgba=(0, 0, 1, 1), cache_dir=tmp_path) != p1


def test_planar_kinematics_matches_pybullet_link_states():
    """Our 2-D forward kinematics against PyBullet's getLinkStates at random states (outside reference)."""
    import pybullet as p

    from jt_tasks.standing_jump.simulate import open_world

    b = model.build_body()
    cid, robot, _, names = open_world(b, 1.0, 1000.0)
    try:
        kin = PlanarKinematics(b, names)
        link_of = {p.getJointInfo(robot, i, physicsClientId=cid)[12].decode(): i for i in range(len(names))}
        rng = np.random.default_rng(0)
        for _ in range(3):
            q = rng.uniform(-1, 1, len(names))
            qd = rng.uniform(-3, 3, len(names))
            for i in range(len(names)):
                p.resetJointState(robot, i, q[i], qd[i], physicsClientId=cid)
            fr = kin.frame(q, qd)
            states = p.getLinkStates(robot, list(range(len(names))), computeLinkVelocity=1,
                                     computeForwardKinematics=1, physicsClientId=cid)
            com = np.zeros(3)
            vel = np.zeros(3)
            for k, link in enumerate(b.links):
                s = states[link_of[link.name]]
                assert s[0][0] == pytest.approx(fr.link_com[k][0], abs=1e-5)
                assert s[0][2] == pytest.approx(fr.link_com[k][1], abs=1e-5)
                assert s[6][0] == pytest.approx(fr.link_vel[k][0], abs=1e-4)
                assert s[6][2] == pytest.approx(fr.link_vel[k][1], abs=1e-4)
                assert s[7][1] == pytest.approx(fr.omega[k], abs=1e-4)
                com += link.mass * np.array(s[0])
                vel += link.mass * np.array(s[6])
            assert com[[0, 2]] / b.mass == pytest.approx(fr.com, abs=1e-5)
            assert vel[[0, 2]] / b.mass == pytest.approx(fr.com_vel, abs=1e-4)
    finally:
        p.disconnect(cid)


def test_angular_momentum_is_conserved_in_free_flight():
    """No gravity, no ground contact, no torques: the planar angular momentum about the CoM stays put."""
    import pybullet as p

    from jt_tasks.standing_jump.simulate import open_world

    b = model.build_body()
    cid, robot, _, names = open_world(b, 1.0, 1000.0)
    try:
        p.setGravity(0, 0, 0, physicsClientId=cid)
        kin = PlanarKinematics(b, names)
        rng = np.random.default_rng(1)
        for i in range(len(names)):
            p.resetJointState(robot, i, 0.3 * rng.normal() + (3.0 if names[i] == "root_z" else 0.0),
                              rng.normal(), physicsClientId=cid)
        Ls = []
        for _ in range(200):
            js = p.getJointStates(robot, range(len(names)), physicsClientId=cid)
            Ls.append(kin.angular_momentum(kin.frame([s[0] for s in js], [s[1] for s in js])))
            p.stepSimulation(physicsClientId=cid)
        assert abs(Ls[0]) > 0.1
        assert np.ptp(Ls) < 0.02 * abs(Ls[0]) + 1e-3
    finally:
        p.disconnect(cid)
