"""Our dynamics against PyBullet: its simulator (every model it can drive) and its
calculateMassMatrix / calculateInverseDynamics (where those are exact: revolute-only bodies)."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from dynamics_worlds import CHARACTERS, REVOLUTE_ONLY, SIMULABLE, state_in_limits

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")


@pytest.mark.parametrize("fixed", [False, True], ids=["floating", "fixed"])
@pytest.mark.parametrize("name", SIMULABLE)
def test_one_step_of_pybullet_matches_aba(worlds, name, fixed):
    """stepSimulation from random (q, qd) under random torques and gravity: the velocity change
    equals dt * aba(q, qd, tau) -- checks M, C (gravity, Coriolis) and the coordinate layout."""
    import pybullet as pb

    from toolkit.dynamics.aba import aba
    from jt_bullet.body import BulletBody

    w = worlds(name, fixed)
    io = BulletBody(w.client, w.character.body_id, w.model)
    dt = 1e-4
    pb.setTimeStep(dt, physicsClientId=w.client)
    rng = np.random.default_rng(7)
    for _ in range(3):
        q, qd = state_in_limits(w, rng)
        tau = rng.normal(size=w.model.n_v) * 5.0
        tau[: io.base_dofs] = 0.0
        io.reset(q, qd)
        q_rb, qd_rb = (x.copy() for x in io.read())  # read() reuses its buffers
        io.write_torques(tau)
        io.step()
        _, qd2 = io.read()
        qdd_sim = (qd2 - qd_rb) / dt
        qdd = aba(w.model, w.data, q_rb, qd_rb, tau)
        scale = np.abs(qdd).max()
        assert np.abs(qdd_sim - qdd).max() <= 1e-8 * scale + 1e-6, name


@pytest.mark.parametrize("name", REVOLUTE_ONLY)
def test_mass_matrix_and_bias_equal_pybullet_fixed_base(worlds, name):
    """calculateMassMatrix / calculateInverseDynamics(q, qd, 0) for a fixed base (PyBullet
    assumes the base at identity orientation in these calls, so we place it there)."""
    import pybullet as pb

    from toolkit.dynamics.crba import crba
    from toolkit.dynamics.model import Data
    from toolkit.dynamics.rnea import bias

    w = worlds(name, True)
    model = copy.deepcopy(w.model)  # the session's world is shared: its own model keeps its base pose
    model.set_base_pose(model.tree_p[0], (0, 0, 0, 1))
    data = Data(model)
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, qd = model.random_state(rng)
        M_pb = np.array(pb.calculateMassMatrix(w.character.body_id, q.tolist(),
                                               physicsClientId=w.client))
        C_pb = np.array(pb.calculateInverseDynamics(w.character.body_id, q.tolist(), qd.tolist(),
                                                    [0.0] * len(q), physicsClientId=w.client))
        M = crba(model, data, q)
        C = bias(model, data, q, qd)
        assert np.allclose(M, M_pb, rtol=1e-9, atol=1e-10 * np.abs(M).max())
        assert np.allclose(C, C_pb, rtol=1e-9, atol=1e-9 * np.abs(C).max())


@pytest.mark.parametrize("name", REVOLUTE_ONLY)
def test_mass_matrix_and_bias_equal_pybullet_floating_base(worlds, name):
    """Floating base at identity orientation. PyBullet's calls take joint-only q (mass matrix)
    and base velocities ordered [w, v]; they return M in [w, v] order and C as [f, n, joints]."""
    import pybullet as pb

    from toolkit.dynamics.crba import crba
    from toolkit.dynamics.rnea import bias

    w = worlds(name, False)
    rng = np.random.default_rng(4)
    n = w.model.n_v
    perm = np.r_[3, 4, 5, 0, 1, 2, 6:n]  # ours [v, w, joints] -> PyBullet's [w, v, joints]
    for _ in range(3):
        q, qd = w.model.random_state(rng)
        q[3:7] = (0, 0, 0, 1)
        M_pb = np.array(pb.calculateMassMatrix(w.character.body_id, q[7:].tolist(),
                                               physicsClientId=w.client))
        qd_pb = np.r_[qd[3:6], qd[0:3], qd[6:]]
        C_pb = np.array(pb.calculateInverseDynamics(w.character.body_id, q.tolist(),
                                                    qd_pb.tolist(), [0.0] * n,
                                                    physicsClientId=w.client))
        M = crba(w.model, w.data, q)
        C = bias(w.model, w.data, q, qd)
        assert np.allclose(M[np.ix_(perm, perm)], M_pb, rtol=1e-9, atol=1e-10 * np.abs(M).max())
        assert np.allclose(C, C_pb, rtol=1e-9, atol=1e-9 * np.abs(C).max())


def test_snake_matches_pybullet_stable_pd_exactly(worlds):
    """For the snakes PyBullet's STABLE_PD_CONTROL model (inertias from the box shapes) equals
    the URDF inertias, so its one-step result must equal exact SPD (MABA) -- an outside check of
    the spherical-joint SPD terms (predicted pose, log map) and the floating base."""
    import pybullet as pb

    from jt_bullet.body import BulletBody
    from toolkit.dynamics.maba import maba

    w = worlds("snake36", False)
    ch = w.character
    io = BulletBody(w.client, ch.body_id, w.model)
    dt = 1.0 / 600.0
    pb.setTimeStep(dt, physicsClientId=w.client)
    rng = np.random.default_rng(11)
    for _ in range(3):
        q, qd = state_in_limits(w, rng)
        qt, _ = w.model.random_state(rng)
        io.reset(q, qd)
        io.stable_pd(qt, ch.kp, ch.kd, np.full(w.model.n_v, 1e9))
        io.step()
        _, qd2 = io.read()
        _, qdd = maba(w.model, w.data, q, qd, qt, ch.kp, ch.kd, dt)
        ref = qd + dt * qdd
        assert np.abs(qd2 - ref).max() <= 1e-8 * np.abs(dt * qdd).max()


def test_snake195_exceeds_pybullet_api():
    """PyBullet's shared-memory API carries at most 128 position coordinates; BulletBody says so
    rather than reading garbage."""
    from jt_bullet.body import PYBULLET_MAX_Q, BulletBody

    class Fake:
        n_q, name = 259, "snake195"

    assert Fake.n_q > PYBULLET_MAX_Q
    with pytest.raises(ValueError, match="MAX_DEGREE_OF_FREEDOM"):
        BulletBody(0, 0, Fake())  # type: ignore[arg-type]


def test_characters_cover_thesis_table_2_1(worlds):
    """n and d of thesis Table 2.1 (humanoid 34/13, snakes n = d)."""
    got = {name: (worlds(name).model.n_v, worlds(name).model.depth) for name in CHARACTERS}
    assert got["humanoid"] == (34, 13)
    for name, n in (("snake36", 36), ("snake72", 72), ("snake195", 195)):
        assert got[name] == (n, n)


def _tilted_urdf() -> str:
    """Joint origins with rpy, off-diagonal inertias, COM offsets, a fixed link mid-chain: the
    frame conventions the thesis characters alone would leave untested."""
    from scipy.spatial.transform import Rotation as R

    rng = np.random.default_rng(0)

    def link(name):
        rot = R.from_rotvec(rng.normal(size=3)).as_matrix()
        I = rot @ np.diag(rng.uniform(0.02, 0.05, size=3)) @ rot.T
        c = rng.normal(size=3) * 0.05
        return (f'<link name="{name}"><inertial><origin xyz="{c[0]} {c[1]} {c[2]}"/>'
                f'<mass value="{rng.uniform(0.5, 2)}"/><inertia ixx="{I[0, 0]}" iyy="{I[1, 1]}" '
                f'izz="{I[2, 2]}" ixy="{I[0, 1]}" ixz="{I[0, 2]}" iyz="{I[1, 2]}"/></inertial>'
                '</link>')

    def joint(name, kind, parent, child):
        xyz, rpy, ax = rng.normal(size=3) * 0.2, rng.normal(size=3), rng.normal(size=3)
        ax /= np.linalg.norm(ax)
        return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
                f'<origin xyz="{xyz[0]} {xyz[1]} {xyz[2]}" rpy="{rpy[0]} {rpy[1]} {rpy[2]}"/>'
                f'<axis xyz="{ax[0]} {ax[1]} {ax[2]}"/>'
                + ('<limit lower="-10" upper="10" effort="100" velocity="100"/>'
                   if kind == "prismatic" else "") + '</joint>')

    parts = [link("base"), link("a"), joint("ja", "spherical", "base", "a"), link("b"),
             joint("jb", "continuous", "a", "b"), link("f"), joint("jf", "fixed", "b", "f"),
             link("c"), joint("jc", "spherical", "f", "c"), link("d"),
             joint("jd", "prismatic", "a", "d")]
    return '<robot name="tilted">' + "".join(parts) + "</robot>"


@pytest.mark.parametrize("fixed", [False, True], ids=["floating", "fixed"])
def test_rotated_frames_and_inertias_match_pybullet(tmp_path, fixed):
    import pybullet as pb

    from toolkit.dynamics.aba import aba
    from jt_bullet.body import BulletBody
    from jt_bullet.model import model_from_bullet
    from toolkit.dynamics.model import Data

    path = tmp_path / "tilted.urdf"
    path.write_text(_tilted_urdf())
    c = pb.connect(pb.DIRECT)
    try:
        pb.setGravity(0, -9.8, 0, physicsClientId=c)
        dt = 1e-4
        pb.setTimeStep(dt, physicsClientId=c)
        b = pb.loadURDF(str(path), [0, 1, 0], useFixedBase=fixed, physicsClientId=c,
                        flags=pb.URDF_USE_INERTIA_FROM_FILE)
        for j in range(pb.getNumJoints(b, physicsClientId=c)):
            pb.changeDynamics(b, j, jointDamping=0, linearDamping=0, angularDamping=0,
                              physicsClientId=c)
            if pb.getJointInfo(b, j, physicsClientId=c)[2] == pb.JOINT_SPHERICAL:
                pb.setJointMotorControlMultiDof(b, j, pb.POSITION_CONTROL,
                                                targetPosition=[0, 0, 0, 1], positionGain=0,
                                                velocityGain=1, force=[0, 0, 0], physicsClientId=c)
            else:
                pb.setJointMotorControl2(b, j, pb.VELOCITY_CONTROL, force=0, physicsClientId=c)
        pb.changeDynamics(b, -1, linearDamping=0, angularDamping=0, physicsClientId=c)
        m = model_from_bullet(c, b, floating=not fixed)
        d = Data(m)
        io = BulletBody(c, b, m)
        rng = np.random.default_rng(1)
        for _ in range(3):
            q, qd = m.random_state(rng, 0.5)
            q[m.q_idx[-1]] = 0.3  # prismatic joint well inside its limits
            tau = rng.normal(size=m.n_v)
            tau[:io.base_dofs] = 0.0
            io.reset(q, qd)
            q0, qd0 = (x.copy() for x in io.read())
            io.write_torques(tau)
            io.step()
            qdd = aba(m, d, q0, qd0, tau)
            assert np.abs((io.read()[1] - qd0) / dt - qdd).max() <= 1e-8 * np.abs(qdd).max() + 1e-6
    finally:
        pb.disconnect(c)
