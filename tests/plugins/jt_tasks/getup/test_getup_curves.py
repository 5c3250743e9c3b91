"""Feature curves: cubic B-splines with 9 control points over eq 1's s (003 §4.1, §5.5)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from jt_tasks.getup.curves import REFERENCE, FeatureCurve, build_curves, reference_curve, replay_score

CTRL = np.stack([np.linspace(0.1, 1.3, 9), np.full(9, 1.5) + 0.1 * np.sin(np.arange(9)),
                 np.linspace(0.1, 1.6, 9) ** 2 / 1.6], axis=1)


def test_evaluation_matches_scipy_bspline():
    from scipy.interpolate import BSpline

    c = FeatureCurve("a", CTRL, 2.0)
    knots = np.concatenate([np.zeros(3), np.linspace(0, 1, 7), np.ones(3)])  # clamped, uniform inside
    ref = BSpline(knots, CTRL, 3)
    s = np.linspace(0.0, 1.0, 101)
    np.testing.assert_allclose(c.at_s(s), ref(s), atol=1e-12)
    np.testing.assert_allclose(c(2.0 * s), ref(s), atol=1e-12)  # t = s T
    # unclamped cardinal spline: scipy over the valid span [t_3, t_9] mapped to [0, 1]
    u = FeatureCurve("u", CTRL, 2.0, clamped=False)
    kn = (np.arange(13) - 3) / 6.0
    np.testing.assert_allclose(u.at_s(s), BSpline(kn, CTRL, 3)(s), atol=1e-12)


def test_eq1_clamp_and_ends():
    c = FeatureCurve("a", CTRL, 2.0)
    assert c.s(1.0) == pytest.approx(0.5)
    assert c.s(2.0) == 1.0 and c.s(7.0) == 1.0  # s = min((t - t0) / T, 1): the standing phase holds p(1)
    np.testing.assert_allclose(c(5.0), c(2.0))
    np.testing.assert_allclose(c.start, CTRL[0], atol=1e-12)  # clamped: starts at the fallen value
    np.testing.assert_allclose(c.end, CTRL[-1], atol=1e-12)
    assert c.scaled(2.0)(4.0) == pytest.approx(c(2.0))


def test_reference_curves_from_the_clips_and_mirrors():
    assert set(REFERENCE) == {"facedown", "facedown_mirror", "faceup", "faceup_mirror"}
    down, mir = reference_curve("facedown"), reference_curve("facedown_mirror")
    assert down.control.shape == (9, 3) and down.duration == pytest.approx(3.03, abs=0.01)
    assert math.degrees(down.start[2]) == pytest.approx(157.0, abs=1.0)
    assert down.end[0] == pytest.approx(1.367, abs=0.01)  # the standing neck above the ground the pose rests on
    np.testing.assert_allclose(mir.control[:, 1], math.pi - down.control[:, 1], atol=1e-6)
    # notes: the 9-point curves replayed through r_h r_θ, mean 0.78 / 0.73 (facedown / faceup)
    assert replay_score(down)["mean"] == pytest.approx(0.78, abs=0.01)
    assert replay_score(reference_curve("faceup"))["mean"] == pytest.approx(0.73, abs=0.01)
    assert replay_score(reference_curve("faceup", extraction="lstsq"))["mean"] > 0.75


def test_authored_curves_durations_and_bad_input():
    authored = {"sit": {"h": CTRL[:, 0].tolist(), "theta_x": CTRL[:, 1].tolist(), "theta_z": CTRL[:, 2].tolist(),
                        "duration": 3.0}}
    cs = build_curves(["faceup", "sit"], authored, None)
    assert [c.name for c in cs] == ["faceup", "sit"] and cs[1].duration == 3.0
    cs = build_curves(["sit"], authored, [2.5, 5.1, 7.6], time_scale=2.0)
    assert [c.duration for c in cs] == pytest.approx([5.0, 10.2, 15.2])
    with pytest.raises(KeyError, match="unknown curve"):
        build_curves(["nope"], authored, None)
    bad = {"sit": {**authored["sit"], "h": [0.1] * 8}}
    with pytest.raises(ValueError, match="8 control points, needs 9"):
        build_curves(["sit"], bad, None)
    c = cs[0]
    assert FeatureCurve.from_dict(c.to_dict()).to_dict() == c.to_dict()


def test_a_clip_start_and_its_curve_measure_heights_from_the_same_ground():
    """The simulated neck height at a clip's start pose equals its curve's p_h(0) to 1 cm (issue 29:
    +3.6 cm facedown, +4.8 cm faceup, when the curves measured heights above the mocap's y = 0 and
    the starts were lifted onto the ground); the facedown curve also ends at the standing start's
    height."""
    from toolkit import plugins
    from toolkit.config import compose

    env = plugins.load("task", "getup")(compose(["task=getup", "action=raw", "task.n_fallen=0"])).make_env(seed=0)
    try:
        seen = 0
        for i, c in enumerate(env.curves):
            if not c.clip:
                continue
            env.reset(options={"kind": "clip", "curve": i})
            assert env.measure()["features"][0] == pytest.approx(c(0.0)[0], abs=0.01), c.name
            if c.name == "facedown":  # the standing start is this clip's last frame
                env.reset(options={"kind": "standing", "curve": i})
                assert env.measure()["features"][0] == pytest.approx(c(c.duration)[0], abs=0.01)
            seen += 1
        assert seen == 4
    finally:
        env.close()
