"""Uniform cubic B-spline curves against scipy.interpolate.BSpline."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import BSpline

from toolkit.motion.splines import BSplineCurve, N_CONTROL, basis_matrix, greville, normalised_time, uniform_knots

S = np.concatenate([np.linspace(0, 1, 101), [1e-12, 0.5 - 1e-12, 1 - 1e-12]])


@pytest.mark.parametrize("clamped", [True, False])
def test_matches_scipy(clamped: bool):
    rng = np.random.default_rng(0)
    ctrl = rng.normal(size=N_CONTROL)
    curve = BSplineCurve(ctrl, clamped)
    ref = BSpline(curve.knots, ctrl, 3, extrapolate=False)
    np.testing.assert_allclose(curve(S), ref(S), atol=1e-12)
    # vector-valued control points
    ctrl3 = rng.normal(size=(N_CONTROL, 3))
    np.testing.assert_allclose(BSplineCurve(ctrl3, clamped)(S), BSpline(curve.knots, ctrl3, 3)(S), atol=1e-12)
    # basis: partition of unity, non-negative
    b = basis_matrix(S, curve.knots)
    assert b.shape == (len(S), N_CONTROL)
    np.testing.assert_allclose(b.sum(axis=1), 1.0, atol=1e-12)
    assert np.all(b >= -1e-15)


def test_clamped_end_points_and_knots():
    k = uniform_knots(9)
    assert len(k) == 13 and np.all(k[:4] == 0) and np.all(k[-4:] == 1)
    np.testing.assert_allclose(np.diff(k[3:10]), 1 / 6)
    curve = BSplineCurve(np.arange(9.0) ** 2)
    assert curve(0.0) == pytest.approx(0.0) and curve(1.0) == pytest.approx(64.0)
    assert curve(-3.0) == curve(0.0) and curve(7.0) == curve(1.0)  # s is clamped to [0, 1]
    with pytest.raises(ValueError):
        uniform_knots(3)


def test_time_normalisation_eq1():
    np.testing.assert_allclose(normalised_time([0.5, 1.0, 2.0, 9.0], t0=1.0, duration=2.0), [0, 0, 0.5, 1])
    curve = BSplineCurve(np.linspace(0.1, 1.3, 9))
    assert curve.at_time(3.0, t0=1.0, duration=2.0) == pytest.approx(1.3)
    assert curve.at_time(2.0, 1.0, 2.0) == pytest.approx(curve(0.5))


def test_fitting_from_samples():
    s = np.linspace(0, 1, 200)
    # a feature that is itself a spline is recovered exactly by least squares
    truth = BSplineCurve(np.random.default_rng(1).normal(size=9))
    fit = BSplineCurve.from_samples(s, truth(s), method="lstsq")
    np.testing.assert_allclose(fit.control, truth.control, atol=1e-9)
    # 003 §4.1: control points = the feature sampled at nine equally spaced instants
    g = greville(9)
    np.testing.assert_allclose(g, [0, 1 / 18, 1 / 6, 2 / 6, 3 / 6, 4 / 6, 5 / 6, 17 / 18, 1])
    feat = np.sin(3 * s)
    samp = BSplineCurve.from_samples(s, feat)
    np.testing.assert_allclose(samp.control, np.sin(3 * g), atol=1e-4)
    assert np.max(np.abs(samp(s) - feat)) < 0.05  # (1/8 spacing: 0.18)
    lin = BSplineCurve.from_samples(s, 0.3 + 2 * s)  # linear features are reproduced exactly
    np.testing.assert_allclose(lin(s), 0.3 + 2 * s, atol=1e-12)
    flat = BSplineCurve.from_samples(s, np.full((200, 3), 2.0))
    np.testing.assert_allclose(flat(s), 2.0)
    with pytest.raises(ValueError):
        BSplineCurve.from_samples(s, feat, method="nope")
