"""``spd=servo`` (PyBullet's constraint motors): the shared suite, its step-based protocol, its
bounds and its bad values."""

from __future__ import annotations

import numpy as np
import pytest
from jt_bullet.testing import BulletSPDWorlds, make_world
from toolkit.testing.spd import DT, SPDBackendSuite

from jt_spd.servo import ServoBackend


class TestServoBackend(BulletSPDWorlds, SPDBackendSuite):
    backend_cls = ServoBackend
    reference_exact = False


def test_a_fixed_arm_reaches_its_target_and_the_torque_limit_bounds_it():
    """A fixed-base humanoid hanging in gravity: with the character's limits the motors bring every
    joint to a target 0.3 rad away within 0.2 s; with limits of 1 N·m they cannot hold the legs up."""
    import pybullet as pb

    from toolkit.motion import rotations as rot

    c, ch, io = make_world("humanoid", fixed=True, self_collision=False)
    try:
        model = io.model
        target = np.array(ch.q_init)
        k = 0
        for nq in io.nq_j:  # every joint turned 0.3 rad about its own x axis
            sl = slice(7 + k, 7 + k + nq) if io.floating else slice(k, k + nq)
            if nq == 4:  # (revolute joints kept: some rest at a limit)
                target[sl] = rot.quat_multiply(target[sl], rot.quat_from_axis_angle(np.array([1.0, 0.0, 0.0]), 0.3))
            k += nq
        errors = {}
        for name, scale in (("limits", 1.0), ("weak", None)):
            b = ServoBackend(None)
            b.bind(io)
            io.reset(ch.q_init, np.zeros(model.n_v))
            lim = np.array(ch.torque_limit, dtype=float) if scale else np.ones(model.n_v)
            for _ in range(120):
                b.apply(target, ch.kp, ch.kd, lim)
                io.step()
            q, _ = io.read()
            errors[name] = float(np.abs(q - target).max())
        assert errors["limits"] < 0.005  # quaternion components: 0.3 rad is ~0.15 away
        assert errors["weak"] > 0.05
    finally:
        pb.disconnect(c)


@pytest.mark.parametrize("key,value", [("position_gain", 0.0), ("velocity_gain", 1.5)])
def test_a_gain_outside_zero_to_one_is_one_line(key, value):
    from omegaconf import OmegaConf
    from toolkit.errors import JtError

    with pytest.raises(JtError, match=rf"spd.{key}=.*\(0, 1\]"):
        ServoBackend(OmegaConf.create({"name": "servo", key: value}))


def test_a_bad_gain_stops_the_run_before_it_opens():
    """Checked at composition (``check_run``), so no run is written for it."""
    from toolkit.config import compose
    from toolkit.errors import JtError

    assert compose(["task=getup", "spd=servo"]).spd.name == "servo"  # the defaults pass
    with pytest.raises(JtError, match=r"spd.position_gain=2: must be in \(0, 1\]"):
        compose(["task=getup", "spd=servo", "spd.position_gain=2"])
