"""The four SPD solvers agree on every model; the public API's options behave."""

from __future__ import annotations

import numpy as np
import pytest
from dynamics_worlds import CHARACTERS

CASES = [(n, f) for n in CHARACTERS for f in (False, True)]
IDS = [f"{n}-{'fixed' if f else 'floating'}" for n, f in CASES]


@pytest.mark.parametrize(("name", "fixed"), CASES, ids=IDS)
def test_all_methods_return_the_same_torques(worlds, name, fixed):
    from toolkit.dynamics.spd import METHODS, spd_torques

    w = worlds(name, fixed)
    m, d, ch = w.model, w.data, w.character
    rng = np.random.default_rng(8)
    n_states = 1 if m.n_v > 100 else 3  # PCG on the 195-DoF chain takes ~50 ms per solve
    for _ in range(n_states):
        q, qd = m.random_state(rng)
        qt, _ = m.random_state(rng)
        qdt = rng.normal(size=m.n_v)
        out = {k: spd_torques(m, d, q, qd, qt, ch.kp, ch.kd, 1 / 600, method=k, qd_target=qdt)
               for k in METHODS}
        ref = out["df"]
        for k, tau in out.items():
            assert np.abs(tau - ref).max() <= 1e-8 * np.abs(ref).max(), (k, name)


def test_tau_ext_enters_the_dynamics_not_the_torques(worlds):
    """(M + Kd dt) qdd = Q + tau_ext - C; gravity compensation via tau_ext = C leaves M + K."""
    from toolkit.dynamics.crba import crba
    from toolkit.dynamics.rnea import bias
    from toolkit.dynamics.spd import METHODS, spd_torques

    w = worlds("atlas")
    m, d, ch = w.model, w.data, w.character
    rng = np.random.default_rng(6)
    q, qd = m.random_state(rng)
    qt, _ = m.random_state(rng)
    C = bias(m, d, q, qd)
    A = crba(m, d, q) + np.diag(ch.kd / 600)
    for k in METHODS:
        tau = spd_torques(m, d, q, qd, qt, ch.kp, ch.kd, 1 / 600, method=k, tau_ext=C)
        Q = tau + ch.kd / 600 * d.qdd
        assert np.abs(A @ d.qdd - Q).max() <= 1e-9 * np.abs(Q).max(), k


def test_torque_limit_clips_after_the_solve(worlds):
    from toolkit.dynamics.spd import spd_torques

    w = worlds("humanoid")
    m, d, ch = w.model, w.data, w.character
    rng = np.random.default_rng(2)
    q, qd = m.random_state(rng)
    qt, _ = m.random_state(rng)
    free = spd_torques(m, d, q, qd, qt, ch.kp, ch.kd, 1 / 600)
    qdd_free = d.qdd.copy()
    clipped = spd_torques(m, d, q, qd, qt, ch.kp, ch.kd, 1 / 600, torque_limit=ch.torque_limit)
    assert np.all(np.abs(clipped) <= ch.torque_limit)
    assert np.any(np.abs(free) > ch.torque_limit)  # the random pose needs more than the limits
    assert np.array_equal(clipped, np.clip(free, -ch.torque_limit, ch.torque_limit))
    assert np.array_equal(d.qdd, qdd_free)  # the solve itself is unchanged


def test_spherical_error_uses_the_log_map(worlds):
    """At rest with dt -> 0 the SPD torque is kp * rotation vector from q to the target."""
    from scipy.spatial.transform import Rotation as R

    from toolkit.dynamics.spd import spd_torques

    w = worlds("humanoid", True)
    m, d = w.model, w.data
    q = m.neutral()
    qt = q.copy()
    rotvec = np.array([0.4, -0.3, 0.9])  # chest (first joint) target
    qt[0:4] = R.from_rotvec(rotvec).as_quat()
    kp = np.zeros(m.n_v)
    kp[0:3] = 100.0
    tau = spd_torques(m, d, q, np.zeros(m.n_v), qt, kp, np.zeros(m.n_v), 1e-9)
    assert np.allclose(tau[0:3], 100.0 * rotvec, rtol=1e-6)
    assert np.all(tau[3:] == 0.0)


def test_unactuated_root_ignores_root_targets(worlds):
    from toolkit.dynamics.spd import spd_torques

    w = worlds("humanoid")
    m, d, ch = w.model, w.data, w.character
    rng = np.random.default_rng(4)
    q, qd = m.random_state(rng)
    qt, _ = m.random_state(rng)
    a = spd_torques(m, d, q, qd, qt, ch.kp, ch.kd, 1 / 600)
    qt[0:7] = np.nan  # never read when kp = kd = 0 on the root
    b = spd_torques(m, d, q, qd, qt, ch.kp, ch.kd, 1 / 600)
    assert np.array_equal(a, b)


def test_unknown_method_is_one_clear_error(worlds):
    from toolkit.dynamics.spd import spd_torques

    w = worlds("laikago")
    q = w.model.neutral()
    with pytest.raises(ValueError, match="unknown SPD method 'lu'"):
        spd_torques(w.model, w.data, q, np.zeros(w.model.n_v), q, w.character.kp,
                    w.character.kd, 0.01, method="lu")


def test_importing_toolkit_dynamics_is_light():
    import subprocess
    import sys

    code = ("import sys, toolkit.dynamics as d; "
            "assert 'numba' not in sys.modules and 'pybullet' not in sys.modules; "
            "print(sorted(d.__all__))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "spd_torques" in out.stdout
