"""Stable PD of the planar jumper by jt's SPD backends, against PyBullet's own M and C."""

from __future__ import annotations

import numpy as np
import pytest
from omegaconf import OmegaConf

from jt_tasks.standing_jump import StandingJumpTask
from jt_tasks.standing_jump.model import build_body
from jt_bullet.model import model_from_bullet
from jt_tasks.standing_jump.simulate import SimSettings, open_world, simulate, spd_solver
from toolkit.errors import JtError

DT = 1.0 / 600.0
METHODS = ("maba", "df", "sf", "pcg")


@pytest.fixture(scope="module")
def world():
    import pybullet as p

    cid, robot, ground, names = open_world(build_body(80.0, 1.60), 1.0, 600.0)
    yield p, cid, robot, names
    p.disconnect(cid)


def reference_spd(p, cid, robot, q, qd, qt, qdt, kp, kd, dt):
    """Tan et al.'s SPD from PyBullet's calculateMassMatrix / calculateInverseDynamics (outside ref)."""
    n = len(q)
    M = np.asarray(p.calculateMassMatrix(robot, q.tolist(), physicsClientId=cid))
    C = np.asarray(p.calculateInverseDynamics(robot, q.tolist(), qd.tolist(), [0.0] * n,
                                              physicsClientId=cid))
    pos = q + qd * dt - qt
    qdd = np.linalg.solve(M + np.diag(kd * dt), -C - kp * pos - kd * (qd - qdt))
    return -kp * pos - kd * (qd + qdd * dt - qdt)


def spd_backend(spd, cid, robot):
    """The registry backend of ``spd`` bound to the robot's model (fixed base, then the three root
    joints and the 16 hinges in PyBullet joint order), and that model."""
    backend = spd_solver(spd)
    model = model_from_bullet(cid, robot)
    backend.bind(model)
    return backend, model


def random_case(rng, n):
    q, qd = rng.normal(size=n), 2.0 * rng.normal(size=n)
    kp = np.r_[0.0, 0.0, 0.0, rng.uniform(20.0, 1000.0, n - 3)]  # root x, z, pitch: unactuated
    kd = np.r_[0.0, 0.0, 0.0, rng.uniform(2.0, 100.0, n - 3)]
    qt, qdt = rng.normal(size=n), np.r_[0.0, 0.0, 0.0, rng.normal(size=n - 3)]
    return q, qd, qt, qdt, kp, kd


@pytest.mark.parametrize("method", METHODS)
def test_registry_backends_match_pybullet_spd_on_random_states(world, method):
    p, cid, robot, names = world
    backend, model = spd_backend({"name": method}, cid, robot)
    assert model.n_v == len(names) == 19 and not model.floating
    assert list(model.joint_indices) == list(range(19))  # q layout = PyBullet joint order
    rng = np.random.default_rng(0)
    for _ in range(10):
        q, qd, qt, qdt, kp, kd = random_case(rng, model.n_v)
        ref = reference_spd(p, cid, robot, q, qd, qt, qdt, kp, kd, DT)
        tau = backend.torques(q, qd, qt, kp, kd, DT, qd_target=qdt).copy()
        assert np.abs(tau - ref).max() <= 1e-9 * np.abs(ref).max(), method
        assert np.all(tau[:3] == 0.0)  # the root is not actuated


def test_reduced_gravity_reaches_the_spd_model(world):
    p, cid, robot, _ = world
    backend, model = spd_backend(None, cid, robot)  # no spd group: maba
    assert type(backend).__name__ == "MabaBackend"
    q, qd, qt, qdt, kp, kd = random_case(np.random.default_rng(1), model.n_v)
    try:
        p.setGravity(0.0, 0.0, -4.0, physicsClientId=cid)
        model.gravity[:] = (0.0, 0.0, -4.0)  # what _Episode.set_gravity does with the assist
        ref = reference_spd(p, cid, robot, q, qd, qt, qdt, kp, kd, DT)
        tau = backend.torques(q, qd, qt, kp, kd, DT, qd_target=qdt).copy()
    finally:
        p.setGravity(0.0, 0.0, -9.8, physicsClientId=cid)
    assert np.abs(tau - ref).max() <= 1e-9 * np.abs(ref).max()


def test_bullet_spd_is_refused(world):
    _, cid, robot, _ = world
    with pytest.raises(JtError, match="maba, df, sf or pcg"):
        spd_solver({"name": "bullet"})


def test_task_reads_the_spd_group_and_falls_back_to_maba():
    task = {"name": "standing_jump"}
    assert StandingJumpTask(OmegaConf.create({"task": task})).settings().spd == {"name": "maba"}
    st = StandingJumpTask(OmegaConf.create({"task": task, "spd": {"name": "pcg", "tol": 1e-10}})).settings()
    assert st.spd == {"name": "pcg", "tol": 1e-10}


def test_dense_and_maba_jumps_agree():
    """Same controller, two SPD solvers: the jump is the same (round-off grows only at contacts)."""
    from jt_tasks.standing_jump import params as P

    sp = P.space()
    point = sp.to_dict(sp.defaults())
    a = simulate(point, SimSettings(spd={"name": "maba"}))
    b = simulate(point, SimSettings(spd={"name": "df"}))
    assert a.success and b.success
    assert a.events == b.events
    assert b.height == pytest.approx(a.height, rel=1e-6)
    assert b.e_je == pytest.approx(a.e_je, rel=1e-3)  # contacts amplify 1e-15 differences to ~1e-4
