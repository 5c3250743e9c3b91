"""getup_height, getup_torso, getup_velocity, getup_pose (003 §5.1.2, eqs 4-9), hand-computed."""

from __future__ import annotations

import math

import numpy as np
import pytest

from jt_rewards.getup import GetupHeight, GetupPose, GetupTorso, GetupVelocity, phase_alpha, rotation_angles
from toolkit.testing.reward import RewardTermContract

I4 = [[0.0, 0.0, 0.0, 1.0]] * 3
RECORD = {"h": 1.0, "target_h": 1.2, "target_h_end": 1.3, "theta_x": 1.5, "theta_z": 1.4,
          "target_theta_x": 1.57, "target_theta_z": 1.57, "link_ang_vel": [[1.0, 0.0, 0.0]] * 15,
          "joint_rotations": I4, "neutral_rotations": I4}


def about_x(angle: float) -> list[float]:
    return [math.sin(angle / 2), 0.0, 0.0, math.cos(angle / 2)]


class TestGetupHeight(RewardTermContract):
    cls, entry, record, required = GetupHeight, "getup_height", RECORD, ("h", "target_h")
    cases = [({}, {"h": 1.0, "target_h": 0.5}, math.exp(-0.85)),  # r_h(0.5 m) = e^-0.85 (eq 5)
             ({}, {"h": 0.2, "target_h": 0.7}, math.exp(-0.85)),
             ({}, {"h": 1.3, "target_h": 1.3}, 1.0),
             ({"k": 1.0}, {"h": 0.0, "target_h": 2.0}, math.exp(-2.0))]


class TestGetupTorso(RewardTermContract):
    cls, entry, record, required = GetupTorso, "getup_torso", RECORD, (
        "theta_x", "theta_z", "target_theta_x", "target_theta_z")
    cases = [({}, {"theta_x": 1.0, "theta_z": 2.0, "target_theta_x": 1.0, "target_theta_z": 2.0}, 1.0),
             # 1.5 (|0.2| + |-0.3|) = 0.75 (eq 6)
             ({}, {"theta_x": 1.2, "theta_z": 1.7, "target_theta_x": 1.0, "target_theta_z": 2.0}, math.exp(-0.75))]


class TestGetupVelocity(RewardTermContract):
    cls, entry, record, required = GetupVelocity, "getup_velocity", RECORD, (
        "link_ang_vel", "target_h", "target_h_end")
    a09 = math.exp(-2.0)  # α(φ = 0.9) = e^-2 (eq 8)
    cases = [({}, {"link_ang_vel": 10.0, "target_h": 0.9, "target_h_end": 1.0}, (1 - a09) + a09 * math.exp(-0.5)),
             # stacked norm: 15 links x |(3, 4, 0)| -> sqrt(15 * 25)
             ({}, {"link_ang_vel": [[3.0, 4.0, 0.0]] * 15, "target_h": 1.0, "target_h_end": 1.0},
              math.exp(-0.05 * math.sqrt(375.0))),
             ({}, {"link_ang_vel": 0.0, "target_h": 0.3, "target_h_end": 1.3}, 1.0),
             # φ > 1 (overshooting curve) clamped: α = 1, not e^{+2}
             ({}, {"link_ang_vel": 10.0, "target_h": 1.1, "target_h_end": 1.0}, math.exp(-0.5))]

    def test_alpha_zero_gives_one_and_literal_phi_overshoots(self):
        assert phase_alpha(0.9, 1.0) == pytest.approx(math.exp(-2.0), rel=1e-12)
        assert phase_alpha(1.1, 1.0, clamp_phi=False) == pytest.approx(math.exp(2.0), rel=1e-12)
        assert phase_alpha(0.0, 1.3) == pytest.approx(math.exp(-20.0), rel=1e-12)
        v = GetupVelocity({"clamp_phi": False})({"link_ang_vel": 10.0, "target_h": 1.1, "target_h_end": 1.0})
        assert v < 0  # why φ is clamped by default
        with pytest.raises(ValueError):
            phase_alpha(1.0, 0.0)


class TestGetupPose(RewardTermContract):
    cls, entry, record, required = GetupPose, "getup_pose", RECORD, (
        "joint_rotations", "neutral_rotations", "target_h", "target_h_end")
    cases = [({}, {"joint_rotations": I4, "neutral_rotations": I4, "target_h": 1.3, "target_h_end": 1.3}, 1.0),
             # r_p = 1 at q̂, any rotation (eq 9)
             ({}, {"joint_rotations": [about_x(0.4), about_x(-1.0)], "neutral_rotations": [about_x(0.4), about_x(-1.0)],
                   "target_h": 1.3, "target_h_end": 1.3}, 1.0),
             # full angles 0.5 + 1.0 (not half-angles): exp(-0.1 * 1.5) at α = 1
             ({}, {"joint_rotations": [about_x(0.5), about_x(-1.0)], "neutral_rotations": I4[:2],
                   "target_h": 1.3, "target_h_end": 1.3}, math.exp(-0.15)),
             # α = e^-2: blend
             ({}, {"joint_rotations": [about_x(0.5)], "neutral_rotations": I4[:1], "target_h": 0.9,
                   "target_h_end": 1.0}, (1 - math.exp(-2.0)) + math.exp(-2.0) * math.exp(-0.05))]

    def test_angles_are_sign_invariant_and_full(self):
        q = np.array([about_x(2.0)])
        assert rotation_angles(q, np.array(I4[:1]))[0] == pytest.approx(2.0)
        assert rotation_angles(-q, np.array(I4[:1]))[0] == pytest.approx(2.0)  # q and -q are one rotation
        with pytest.raises(ValueError):
            rotation_angles(np.array(I4), np.array(I4[:2]))
