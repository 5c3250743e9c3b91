"""Closed-form cases: a pendulum, a two-link planar arm, a free rigid body, scalar SPD."""

from __future__ import annotations

import math

import numpy as np
import pytest

G = 9.8


def _load(urdf_text: str, tmp_path, fixed: bool = True):
    import pybullet as pb

    from jt_bullet.model import model_from_bullet
    from toolkit.dynamics.model import Data

    path = tmp_path / "body.urdf"
    path.write_text(urdf_text)
    c = pb.connect(pb.DIRECT)
    pb.setGravity(0, -G, 0, physicsClientId=c)
    b = pb.loadURDF(str(path), [0, 0, 0], useFixedBase=fixed, physicsClientId=c,
                    flags=pb.URDF_USE_INERTIA_FROM_FILE)
    m = model_from_bullet(c, b, floating=not fixed)
    return c, m, Data(m)


def _link(name, m, com, I):
    return (f'<link name="{name}"><inertial><origin xyz="{com[0]} {com[1]} {com[2]}"/>'
            f'<mass value="{m}"/><inertia ixx="{I[0]}" iyy="{I[1]}" izz="{I[2]}" ixy="0" ixz="0" '
            f'iyz="0"/></inertial></link>')


def _joint(name, parent, child, xyz):
    return (f'<joint name="{name}" type="continuous"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}"/><axis xyz="0 0 1"/></joint>')


# two links rotating about z, hanging along -y, each of length l with the centre of mass at l/2
M1, M2, L1, L2, I1, I2 = 1.3, 0.7, 0.5, 0.4, 0.02, 0.011
TWO_LINK = ('<robot name="arm">' + _link("base", 1.0, (0, 0, 0), (0.1, 0.1, 0.1))
            + _link("l1", M1, (0, -L1 / 2, 0), (I1, I1, I1)) + _joint("j1", "base", "l1", "0 0 0")
            + _link("l2", M2, (0, -L2 / 2, 0), (I2, I2, I2))
            + _joint("j2", "l1", "l2", f"0 {-L1} 0") + "</robot>")


def test_two_link_arm_closed_form(tmp_path):
    """M, C of the planar double pendulum (angles from the hanging pose, gravity -y)."""
    import pybullet as pb

    from toolkit.dynamics.crba import crba
    from toolkit.dynamics.rnea import bias

    c, m, d = _load(TWO_LINK, tmp_path)
    try:
        rng = np.random.default_rng(0)
        for _ in range(4):
            q = rng.uniform(-3, 3, size=2)
            qd = rng.normal(size=2)
            a1, a2 = L1 / 2, L2 / 2
            c2 = math.cos(q[1])
            h11 = I1 + I2 + M1 * a1**2 + M2 * (L1**2 + a2**2 + 2 * L1 * a2 * c2)
            h12 = I2 + M2 * (a2**2 + L1 * a2 * c2)
            h22 = I2 + M2 * a2**2
            hh = M2 * L1 * a2 * math.sin(q[1])
            # hanging along -y: potential V = -g (M1 a1 cos q1 + M2 (L1 cos q1 + a2 cos(q1+q2)))
            g1 = G * (M1 * a1 * math.sin(q[0]) + M2 * (L1 * math.sin(q[0])
                                                      + a2 * math.sin(q[0] + q[1])))
            g2 = G * M2 * a2 * math.sin(q[0] + q[1])
            C_ref = np.array([-hh * (2 * qd[0] * qd[1] + qd[1] ** 2) + g1, hh * qd[0] ** 2 + g2])
            assert np.allclose(crba(m, d, q), [[h11, h12], [h12, h22]], atol=1e-12)
            assert np.allclose(bias(m, d, q, qd), C_ref, atol=1e-12)
    finally:
        pb.disconnect(c)


def test_pendulum_scalar_spd_closed_form(tmp_path):
    """One DoF: tau = -kp (q + dt qd - qt) - kd (qd + dt qdd), qdd = (tau - C) / M (eq 2.4)."""
    import pybullet as pb

    from toolkit.dynamics.spd import METHODS, spd_torques

    text = ('<robot name="p">' + _link("base", 1.0, (0, 0, 0), (0.1, 0.1, 0.1))
            + _link("l1", M1, (0, -L1 / 2, 0), (I1, I1, I1)) + _joint("j1", "base", "l1", "0 0 0")
            + "</robot>")
    c, m, d = _load(text, tmp_path)
    try:
        q, qd, qt, kp, kd, dt = 0.3, -1.2, 0.5, 300.0, 30.0, 1.0 / 30.0
        Mq = I1 + M1 * (L1 / 2) ** 2
        Cq = G * M1 * (L1 / 2) * math.sin(q)
        qdd = (-kp * (q + dt * qd - qt) - kd * qd - Cq) / (Mq + kd * dt)
        tau_ref = -kp * (q + dt * qd - qt) - kd * (qd + dt * qdd)
        for method in METHODS:
            tau = spd_torques(m, d, [q], [qd], [qt], [kp], [kd], dt, method=method)
            assert tau[0] == pytest.approx(tau_ref, rel=1e-12), method
            assert d.qdd[0] == pytest.approx(qdd, rel=1e-12), method
    finally:
        pb.disconnect(c)


def test_free_body_mass_matrix_and_gyroscopic_bias(tmp_path):
    """A single floating rigid body: M = diag(m I, R I_b R^T), C = [-m g, w x (R I_b R^T) w]."""
    import pybullet as pb

    from toolkit.dynamics.crba import crba
    from toolkit.dynamics.rnea import bias
    from scipy.spatial.transform import Rotation as R

    Ib = np.array([0.3, 0.5, 0.7])
    c, m, d = _load('<robot name="b">' + _link("base", 2.0, (0, 0, 0), Ib) + "</robot>",
                    tmp_path, fixed=False)
    try:
        rng = np.random.default_rng(5)
        q, qd = m.random_state(rng)
        Rw = R.from_quat(q[3:7]).as_matrix()
        Iw = Rw @ np.diag(Ib) @ Rw.T
        M_ref = np.zeros((6, 6))
        M_ref[:3, :3] = 2.0 * np.eye(3)
        M_ref[3:, 3:] = Iw
        w = qd[3:6]
        C_ref = np.r_[2.0 * np.array([0.0, G, 0.0]), np.cross(w, Iw @ w)]
        assert np.allclose(crba(m, d, q), M_ref, atol=1e-12)
        assert np.allclose(bias(m, d, q, qd), C_ref, atol=1e-12)
    finally:
        pb.disconnect(c)
