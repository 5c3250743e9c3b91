"""Algorithms against each other on random states of every model, fixed and floating base:
CRBA columns = RNEA differences, ABA inverts RNEA, MABA solves (M + Kd dt) qdd = Q - C."""

from __future__ import annotations

import numpy as np
import pytest
from dynamics_worlds import CHARACTERS

CASES = [(n, f) for n in CHARACTERS for f in (False, True)]
IDS = [f"{n}-{'fixed' if f else 'floating'}" for n, f in CASES]


@pytest.mark.parametrize(("name", "fixed"), CASES, ids=IDS)
def test_crba_columns_equal_rnea_differences(worlds, name, fixed):
    from toolkit.dynamics.crba import crba
    from toolkit.dynamics.rnea import rnea

    w = worlds(name, fixed)
    m, d = w.model, w.data
    rng = np.random.default_rng(1)
    q, qd = m.random_state(rng)
    M = crba(m, d, q)
    C = rnea(m, d, q, qd, np.zeros(m.n_v))
    cols = np.empty_like(M)
    for i in range(m.n_v):
        e = np.zeros(m.n_v)
        e[i] = 1.0
        cols[:, i] = rnea(m, d, q, qd, e) - C
    assert np.allclose(M, M.T, atol=1e-12 * np.abs(M).max())
    assert np.abs(cols - M).max() <= 1e-10 * np.abs(M).max()
    assert np.all(np.linalg.eigvalsh(M) > 0)


@pytest.mark.parametrize(("name", "fixed"), CASES, ids=IDS)
def test_aba_inverts_rnea(worlds, name, fixed):
    from toolkit.dynamics.aba import aba
    from toolkit.dynamics.rnea import rnea

    w = worlds(name, fixed)
    m, d = w.model, w.data
    rng = np.random.default_rng(2)
    for _ in range(2):
        q, qd = m.random_state(rng)
        tau = rng.normal(size=m.n_v) * 10
        qdd = aba(m, d, q, qd, tau)
        assert np.abs(rnea(m, d, q, qd, qdd) - tau).max() <= 1e-9 * (1 + np.abs(tau).max())


def _spd_q_reference(m, q, qd, qt, kp, kd, dt):
    """Q of eq 2.20 written independently with scipy rotations (predicted pose, log map)."""
    from scipy.spatial.transform import Rotation as R

    from toolkit.dynamics.model import JT_FREE, JT_SPHERICAL

    Q = np.zeros(m.n_v)
    for i, t in enumerate(m.jtype):
        a, v = m.q_idx[i], m.v_idx[i]
        if t == JT_FREE:
            Q[0:3] = kp[0:3] * (qt[0:3] - q[0:3] - dt * qd[0:3])
            pred = R.from_rotvec(dt * qd[3:6]) * R.from_quat(q[3:7])
            Q[3:6] = kp[3:6] * (R.from_quat(qt[3:7]) * pred.inv()).as_rotvec()
            Q[0:6] -= kd[0:6] * qd[0:6]
        elif t == JT_SPHERICAL:
            pred = R.from_quat(q[a:a + 4]) * R.from_rotvec(dt * qd[v:v + 3])
            e = (pred.inv() * R.from_quat(qt[a:a + 4])).as_rotvec()
            Q[v:v + 3] = kp[v:v + 3] * e - kd[v:v + 3] * qd[v:v + 3]
        elif i > 0:
            Q[v] = kp[v] * (qt[a] - q[a] - dt * qd[v]) - kd[v] * qd[v]
    return Q


SPD_CASES = [(n, f, s) for n, f in CASES for s in (False, True) if not (f and s)]
SPD_IDS = [f"{n}-{'fixed' if f else 'floating'}{'-hand-of-god' if s else ''}"
           for n, f, s in SPD_CASES]


@pytest.mark.parametrize(("name", "fixed", "root_servo"), SPD_CASES, ids=SPD_IDS)
def test_maba_solves_the_spd_system(worlds, name, fixed, root_servo):
    """(M + Kd dt) qdd = Q - C (eq 2.7) with Q from eq 2.20, and tau = Q - Kd dt qdd (eq 2.17);
    with and without the hand-of-God root servo of thesis §2.4.1."""
    from toolkit.dynamics.crba import crba
    from toolkit.dynamics.maba import maba
    from toolkit.dynamics.rnea import bias

    w = worlds(name, fixed)
    m, d = w.model, w.data
    ch = w.character
    rng = np.random.default_rng(3)
    kp, kd = ch.kp.copy(), ch.kd.copy()
    if root_servo:  # thesis §2.4.1 tracking gains for the root
        kp[:6], kd[:6] = 20000.0, 2000.0
    dt = 1.0 / 600.0
    q, qd = m.random_state(rng)
    qt, _ = m.random_state(rng)
    tau, qdd = maba(m, d, q, qd, qt, kp, kd, dt)
    Q = _spd_q_reference(m, q, qd, qt, kp, kd, dt)
    A = crba(m, d, q) + np.diag(kd * dt)
    C = bias(m, d, q, qd)
    scale = np.abs(Q - C).max()
    assert np.abs(A @ qdd - (Q - C)).max() <= 1e-10 * scale
    assert np.allclose(tau, Q - kd * dt * qdd, rtol=1e-12, atol=1e-12 * scale)
    if not root_servo and m.floating:
        assert np.all(tau[:6] == 0.0)
    if root_servo:
        assert np.abs(tau[:6]).max() > 0.0
