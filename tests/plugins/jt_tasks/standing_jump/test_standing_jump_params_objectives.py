"""The 34 parameters, the exact zero-assist case, and the objective terms of 004 eqs 1–6."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from jt_tasks.standing_jump import objectives as O
from jt_tasks.standing_jump import params as P


def test_thirty_four_named_parameters_with_seed_defaults_inside_bounds():
    sp = P.space()
    assert sp.dim == 34  # 004 §3: "we optimize for 34 free parameters"
    assert len(set(sp.names)) == 34
    assert sp.names == P.param_names()
    for prm in sp.params:
        assert prm.low < prm.high
        assert prm.low <= prm.default <= prm.high, prm.name
    # 6 joints x 5 phases + take-off and rise ankles + 2 assist parameters
    assert sum(n.endswith("_ankle") for n in sp.names) == 2
    assert {"takeoff_gravity", "assist_time"} <= set(sp.names)


def test_phase_targets_clip_and_fill_in():
    t = P.phase_targets({"crouch_knee": 99.0, "takeoff_ankle": -0.5})
    assert t["crouch"]["knee"] == P.BOUNDS["knee"][1]
    assert t["takeoff"]["ankle"] == -0.5
    assert t["fall"]["ankle"] == 0.0 and t["land"]["ankle"] == 0.0  # flat feet for landing
    assert t["rise"]["hip"] == P.SEED["rise"]["hip"]
    assert t["stand"] == P.STAND


@pytest.mark.parametrize("g, dur", [(-12.0, 0.5), (-9.8, 0.5), (-9.8 + 0.049, 0.7), (-5.0, 0.0), (-5.0, 5e-4)])
def test_no_assist_is_exactly_natural(g, dur):
    assert P.assist({"takeoff_gravity": g, "assist_time": dur}) == (-9.8, 0.0)


def test_assist_above_the_deadzone():
    g0, dur = P.assist({"takeoff_gravity": -4.0, "assist_time": 0.6})
    assert (g0, dur) == (-4.0, 0.6)
    assert P.assist({"takeoff_gravity": 99.0, "assist_time": 9.0}) == (P.GRAVITY_BOUNDS[1], P.ASSIST_TIME_BOUNDS[1])


def test_effort_and_penalty_terms_follow_the_equations():
    assert O.effort(100.0, 0.0) == pytest.approx(math.log(100.0))
    assert O.effort(100.0, 2.0, w_je=1.0, w_se=5000.0) == pytest.approx(math.log(100.0 + 10000.0))
    # eq 2: zero inside the bracket, w_p (h_p - h_o)^2 outside
    assert O.c_h(2.0, 2.05, 0.1) == 0.0
    assert O.c_h(2.0, 2.3, 0.1) == pytest.approx(5000.0 * 0.09)
    # eq 3: constant f_p outside the landing box
    assert O.c_l(0.1, 0.0, 0.25) == 0.0
    assert O.c_l(0.3, 0.0, 0.25) == 1e5
    assert O.c_l(math.nan, 0.0, 0.25) == 1e5


def test_objectives_and_bsoo_single_objective_round_trip():
    ok = O.jump_objectives(2.0, 1e6, 0.0, failed=False)
    assert ok == pytest.approx([-2.0, math.log(1e6)])
    bad = O.jump_objectives(2.0, 1e6, 0.0, failed=True)
    assert bad == pytest.approx([-2.0 + 1e5, math.log(1e6) + 1e5])
    # f_SO = C_H + C_L + log(...)  (eqs 1, 5)
    assert O.f_so(ok, 2.0, 0.05) == pytest.approx(math.log(1e6))
    assert O.f_so(ok, 2.5, 0.05) == pytest.approx(5000.0 * 0.25 + math.log(1e6))
    assert O.f_so(bad, 2.0, 0.05) == pytest.approx(1e5 + math.log(1e6))
    assert all(math.isfinite(v) for v in O.jump_objectives(math.nan, math.nan, 0.0, failed=True))


def test_non_dominated_matches_brute_force():
    rng = np.random.default_rng(0)
    F = rng.normal(size=(40, 2))
    F[5] = F[3]  # a duplicate
    mask = O.non_dominated(F)
    for i in range(len(F)):
        dominated = any(np.all(F[j] <= F[i]) and np.any(F[j] < F[i]) for j in range(len(F)))
        assert mask[i] == (not dominated)
    valid = np.ones(40, bool)
    valid[np.flatnonzero(mask)[0]] = False
    assert not O.non_dominated(F, valid)[np.flatnonzero(mask)[0]]


def test_hypervolume_of_a_staircase():
    F = np.array([[-3.0, 12.0], [-2.0, 11.0], [-1.0, 10.0], [-2.5, 14.0]])  # the last is dominated
    ref = [0.0, 15.0]
    # rectangles: x from -3..0 with y-heights 3, 4, 5 on the staircase
    expected = 1.0 * 3.0 + 1.0 * 4.0 + 1.0 * 5.0
    assert O.hypervolume(F, ref) == pytest.approx(expected)
    assert O.hypervolume(F, ref, valid=np.array([False, True, True, True])) == pytest.approx(
        0.5 * 1.0 + 1.0 * 4.0 + 1.0 * 5.0)
    assert O.hypervolume(np.array([[1.0, 1.0]]), ref) == 0.0
    # brute force on a grid
    xs = np.linspace(-3, 0, 301)[:-1] + 0.005
    ys = np.linspace(10, 15, 501)[:-1] + 0.005
    cells = sum(any(np.all(f <= [x, y]) for f in F) for x, y in itertools.product(xs[::10], ys[::10]))
    assert cells * (0.1 * 0.1) == pytest.approx(expected, rel=0.05)


def test_hypervolume_curve_is_the_hypervolume_of_every_prefix():
    from jt_tasks.standing_jump.summary import hypervolume_curve

    rng = np.random.default_rng(0)
    F = rng.uniform(0.0, 1.0, size=(40, 2))
    ok = rng.uniform(size=40) > 0.2
    ref = (1.0, 1.0)
    curve = hypervolume_curve(F, ref, ok)
    brute = [O.hypervolume(F[: k + 1], ref, valid=ok[: k + 1]) for k in range(len(F))]
    np.testing.assert_allclose(curve, brute, rtol=1e-12)
    assert np.all(np.diff(curve) >= 0) and curve[-1] > curve[0]
