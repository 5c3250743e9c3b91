"""``spd=bullet`` (PyBullet's C++ STABLE_PD_CONTROL): the shared suite, its step-based protocol,
and how it agrees with exact SPD."""

from __future__ import annotations

import numpy as np
import pytest
from jt_bullet.testing import BulletSPDWorlds, make_world
from toolkit.testing.spd import DT, SPDBackendSuite

from jt_spd.bullet import BulletBackend


class TestBulletBackend(BulletSPDWorlds, SPDBackendSuite):
    backend_cls = BulletBackend
    reference_exact = False

    def test_bind_rejects_a_bare_model(self, humanoid):
        ch = humanoid.character
        with pytest.raises(TypeError, match="BulletBody or a Character"):
            BulletBackend(None).bind(ch.model())


def _one_step(io, q, qd, apply) -> np.ndarray:
    io.reset(q, qd)
    apply()
    io.step()
    return io.read()[1].copy()


def test_matches_exact_spd_where_pybullet_model_is_exact():
    """Snakes: PyBullet's SPD model (inertia from the box shapes) equals the true inertia, so one
    STABLE_PD step equals one step under our MABA torques (PyBullet's own forward dynamics)."""
    import pybullet as pb

    from toolkit.dynamics.model import Data
    from toolkit.dynamics.spd import spd_torques

    c, ch, io = make_world("snake72")
    try:
        model = io.model
        data = Data(model)
        big = np.full(model.n_v, 1e9)
        rng = np.random.default_rng(3)
        for _ in range(2):
            q, qd = model.random_state(rng, 0.5)
            qt, _ = model.random_state(rng)
            qd_b = _one_step(io, q, qd, lambda: io.stable_pd(qt, ch.kp, ch.kd, big))
            tau = spd_torques(model, data, q, qd, qt, ch.kp, ch.kd, DT)
            qd_m = _one_step(io, q, qd, lambda: io.write_torques(tau))
            assert np.abs(qd_b - qd_m).max() <= 1e-7 * np.abs(qd_m - qd).max()
    finally:
        pb.disconnect(c)


def test_humanoid_differs_only_by_pybullets_inertia_model():
    """Humanoid: PyBullet's SPD uses DeepMimic's cRBDModel, whose inertias come from the
    collision shapes, so its step differs from exact SPD; solving our SPD system (same predicted
    pose, log-map errors, Kd dt) with *PyBullet's* M and C (calculateMassMatrix/
    calculateInverseDynamics, flags=1 = that model) reproduces its step."""
    import pybullet as pb

    from toolkit.dynamics.maba import maba, spd_terms_kernel
    from toolkit.dynamics.aba import aba

    c, ch, io = make_world("humanoid", self_collision=False)  # no contacts in the step
    try:
        model = io.model
        from toolkit.dynamics.model import Data

        data = Data(model)
        big = np.full(model.n_v, 1e9)
        rng = np.random.default_rng(5)
        # flags=1 layout: 7 root entries ([v, w, 0]) and 4 per spherical joint ([w, 0])
        keep, k = list(range(6)), 7
        for n in io.nv_j:
            keep += list(range(k, k + n))
            k += 4 if n == 3 else 1
        q, qd = model.random_state(rng, 0.3)
        q[0:3] = (0, 3, 0)
        for i, n in enumerate(io.nv_j):  # knees / elbows inside their joint limits
            if n == 1:
                lo, hi = pb.getJointInfo(ch.body_id, io.joints[i], physicsClientId=c)[8:10]
                q[model.q_idx[i + 1]] = 0.5 * (lo + hi)
        qt, _ = model.random_state(rng)
        qd_b = _one_step(io, q, qd, lambda: io.stable_pd(qt, ch.kp, ch.kd, big))
        pad_v = np.zeros(k)
        pad_v[keep] = qd
        M1 = np.array(pb.calculateMassMatrix(ch.body_id, q.tolist(), flags=1,
                                             physicsClientId=c))[np.ix_(keep, keep)]
        C1 = np.array(pb.calculateInverseDynamics(ch.body_id, q.tolist(), pad_v.tolist(),
                                                  [0.0] * k, flags=1, physicsClientId=c))[keep]
        Q, K = np.zeros(model.n_v), np.zeros(model.n_v)
        spd_terms_kernel(model.mi, q, qd, qt, data.zeros_v, ch.kp, ch.kd, DT, Q, K)
        qdd1 = np.linalg.solve(M1 + np.diag(K), Q - C1)
        tau_pb = Q - K * qdd1  # PyBullet's torques
        qdd_pred = aba(model, data, q, qd, tau_pb)  # ...through the true dynamics
        assert np.abs(qd_b - (qd + DT * qdd_pred)).max() <= 1e-6 * np.abs(DT * qdd_pred).max()
        # whereas exact SPD on the true model is visibly different
        _, qdd_exact = maba(model, data, q, qd, qt, ch.kp, ch.kd, DT)
        assert np.abs(qdd_exact - qdd_pred).max() > 1e-3 * np.abs(qdd_exact).max()
    finally:
        pb.disconnect(c)


def test_standing_humanoid_trajectories_agree():
    """Holding the loaded pose on the ground for 1 s: maba and bullet end within 2 cm."""
    import pybullet as pb

    from jt_spd.maba import MabaBackend

    ends = {}
    for cls in (MabaBackend, BulletBackend):
        c, ch, io = make_world("humanoid", plane=True)
        try:
            b = cls(None)
            b.bind(io if cls.steps_itself else ch.model())
            for _ in range(600):
                b.control(io, ch.q_init, ch.kp, ch.kd, DT, ch.torque_limit)
                io.step()
            ends[cls.__name__] = io.read()[0].copy()
        finally:
            pb.disconnect(c)
    a, b = ends["MabaBackend"], ends["BulletBackend"]
    assert np.abs(a[0:3] - b[0:3]).max() < 0.02
