"""The finite-state controller's pieces, against analytic answers (no simulation)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from jt_tasks.standing_jump import model
from jt_tasks.standing_jump import params as P
from jt_tasks.standing_jump import placement
from jt_tasks.standing_jump.controller import JumpController
from jt_tasks.standing_jump.timing import Timing
from jt_tasks.standing_jump.kinematics import PlanarKinematics
from jt_tasks.standing_jump.model import ROOT_JOINTS


@pytest.fixture(scope="module")
def body():
    return model.build_body()


@pytest.fixture(scope="module")
def kin(body):
    return PlanarKinematics(body, list(ROOT_JOINTS) + body.joint_names)


def pose(body, values: dict, root=(0.0, 1.2, 0.0)) -> list[float]:
    """Joint vector in (root, body.joint_names) order; ``values`` by joint name (missing = 0)."""
    return list(root) + [values.get(j, 0.0) for j in body.joint_names]


def test_time_to_apex_matches_ballistics():
    g = lambda t: -9.8  # noqa: E731
    assert placement.time_to_apex(2.94, g) == pytest.approx(2.94 / 9.8, abs=3e-3)
    assert placement.time_to_apex(-1.0, g) == 0.0
    # reduced gravity g(t) = g0 + (-9.8 - g0) t / T right after take-off:
    # v(t) = v0 + g0 t + (-9.8 - g0) t^2 / 2T for t < T
    g0, T, v0 = -4.0, 0.5, 3.0
    ramp = lambda t: g0 + (-9.8 - g0) * min(t / T, 1.0)  # noqa: E731
    a, b, c = (-9.8 - g0) / (2 * T), g0, v0
    t_in = (-b - math.sqrt(b * b - 4 * a * c)) / (2 * a)
    v_T = v0 + g0 * T + (-9.8 - g0) * T / 2
    expected = t_in if 0 <= t_in <= T else T + v_T / 9.8
    assert placement.time_to_apex(v0, ramp) == pytest.approx(expected, abs=3e-3)
    assert placement.time_to_apex(v0, ramp, t0=T) == pytest.approx(v0 / 9.8, abs=3e-3)


def test_time_to_touchdown_matches_ballistics():
    assert placement.time_to_touchdown(0.5, 0.0) == pytest.approx(math.sqrt(2 * 0.5 / 9.8))
    assert placement.time_to_touchdown(0.0, 1.0) == pytest.approx(2 * 1.0 / 9.8)
    assert placement.time_to_touchdown(0.2, -1.0) == pytest.approx((-1 + math.sqrt(1 + 2 * 9.8 * 0.2)) / 9.8)


def test_targets_are_piecewise_linear_with_the_ramp_slope(body, kin):
    c = JumpController(body, P.phase_targets({}), Timing())
    fr = kin.frame(pose(body, {}), [0.0] * 19)
    a = c.current_targets()
    c._enter("crouch", [(0.4, c.targets["crouch"])], fr)
    c.t_phase = 0.1
    mid, rate = c._targets_and_rates()
    b = c.targets["crouch"]
    assert mid["knee"] == pytest.approx(a["knee"] + 0.25 * (b["knee"] - a["knee"]))
    assert rate["knee"] == pytest.approx((b["knee"] - a["knee"]) / 0.4)
    c.t_phase = 1.0
    held, rate = c._targets_and_rates()
    assert held["knee"] == pytest.approx(b["knee"]) and rate["knee"] == 0.0


def test_virtual_force_torques_push_the_com_back_over_the_feet(body, kin):
    """CoM behind the balance point: J^T f with f forward flexes the ankles' uppers forward."""
    c = JumpController(body, P.phase_targets({}), Timing())
    fr = kin.frame(pose(body, {}, root=(0.0, body.hip_height, 0.0)), [0.0] * 19)
    c.balance_x = fr.com[0] + 0.05  # CoM 5 cm behind the target
    tau = [0.0] * 16
    c._virtual_force(fr, tau)
    names = body.joint_names
    fx = 0.5 * c.tm.vf_kp * 0.05
    for side in ("l", "r"):
        ankle = names.index(f"ankle_{side}")
        # ankle motor (axis -y, acting on the foot) pushes the shank forward: u = (z_com - z_ankle) f
        z_ankle = fr.joint_pos[body.links.index(body.link(f"foot_{side}"))][1]
        assert tau[ankle] == pytest.approx((fr.com[1] - z_ankle) * fx)
        assert tau[ankle] > 0.0
        assert tau[names.index(f"knee_{side}")] < 0.0  # knee motor (axis +y) turns the thigh forward


def test_world_frame_targets_servo_the_world_angle(body, kin):
    """The joint-space target of a world-frame servo makes the child link reach the world angle."""
    c = JumpController(body, P.phase_targets({}), Timing())
    q = pose(body, {"abs": 0.3, "knee_l": 0.5, "knee_r": 0.5}, root=(0.0, 1.0, 0.2))
    fr = kin.frame(q, [0.0, 0.0, 0.7] + [0.0] * 16)
    cmd = c._joint_targets(fr, {})
    names = body.joint_names
    q2 = list(q)
    for j in ("back", "ankle_l"):  # only the world-frame joints move; their parents stay put
        q2[3 + names.index(j)] = cmd.target[names.index(j)]
    fr2 = kin.frame(q2, [0.0] * 19)
    chest = body.links.index(body.link("chest"))
    foot = body.links.index(body.link("foot_l"))
    tg = c.current_targets()
    assert fr2.pitch[chest] == pytest.approx(tg["back"])  # chest lean (axis +y)
    assert -fr2.pitch[foot] == pytest.approx(tg["ankle"])  # foot pitch, toes up + (axis -y)
    # target rates cancel the parent's world rate: damping acts on the world angle's rate
    assert cmd.rate[names.index("back")] == pytest.approx(-0.7)
    # stance hip with a loaded foot servos the pelvis pitch: target = pelvis target - thigh pitch
    thigh = body.links.index(body.link("thigh_l"))
    cmd = c._joint_targets(fr, {foot: 1000.0})
    assert cmd.target[names.index("hip_l")] == pytest.approx(tg["hip"] - fr.pitch[thigh])
    assert cmd.target[names.index("hip_r")] == pytest.approx(tg["hip"])  # unloaded foot: local target


def test_leg_ik_reaches_the_aim_and_clamps_the_knee():
    L1, L2 = 0.38, 0.40
    for dx in (-0.1, 0.0, 0.15):
        hip, knee = placement.leg_ik(dx, 0.2, 0.5, 0.8, L1, L2, 0.3, 1.8, 1.0)
        phi_t = 0.2 - hip
        x = -L1 * math.sin(phi_t) - L2 * math.sin(phi_t + knee)
        assert x == pytest.approx(dx, abs=1e-9)
        assert 0.3 <= knee <= 1.8
    # an aim that needs a straight knee: the knee stops at its minimum and the hip turns the leg
    hip, knee = placement.leg_ik(0.5, 0.0, 0.0, 0.8, L1, L2, 0.3, 1.8, 2.0)
    assert knee == pytest.approx(0.3) and hip > 0.0
    phi_t = -hip
    assert -L1 * math.sin(phi_t) - L2 * math.sin(phi_t + knee) == pytest.approx(0.5, abs=1e-9)


def test_foot_placement_aims_at_the_capture_point(body, kin):
    tm = Timing()
    c = JumpController(body, P.phase_targets({}), tm)
    q = pose(body, {"hip_l": 0.4, "hip_r": 0.4, "knee_l": 0.8, "knee_r": 0.8}, root=(0.0, 1.3, 0.2))
    qd = [0.3, -1.0, 0.0] + [0.0] * 16
    fr = kin.frame(q, qd)
    hip, knee = c._foot_placement(fr, {"hip": 0.4, "knee": 0.8})
    names = body.joint_names
    q2 = list(q)
    for side in ("l", "r"):
        q2[3 + names.index(f"hip_{side}")] = hip
        q2[3 + names.index(f"knee_{side}")] = knee
    fr2 = kin.frame(q2, qd)
    thigh, foot = body.links.index(body.link("thigh_l")), body.links.index(body.link("foot_l"))
    t_td = placement.time_to_touchdown(c.feet_height(fr), fr.com_vel[1])
    vx = fr.com_vel[0]
    capture = fr.com[0] + vx * t_td + vx * math.sqrt(tm.landing_height / 9.8)
    aim = capture - (tm.balance_point * body.foot_length - body.heel_to_ankle) - (fr.joint_pos[thigh][0] + vx * t_td)
    assert fr2.joint_pos[foot][0] - fr2.joint_pos[thigh][0] == pytest.approx(aim, abs=1e-9)
    assert not np.isclose(fr.joint_pos[foot][0] - fr.joint_pos[thigh][0], aim, atol=1e-3)
