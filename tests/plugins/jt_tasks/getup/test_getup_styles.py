"""The five authored get-up styles (003 §5.5): 9 control points, 3 durations, start/end as documented."""

from __future__ import annotations

import math

import numpy as np
import pytest

from jt_tasks.getup.curves import build_curves
from jt_tasks.getup.styles import PRONE, STAND, STYLES, STYLES_DEG, SUPINE
from toolkit.errors import JtError


def deg(v) -> np.ndarray:
    return np.array([v[0], math.radians(v[1]), math.radians(v[2])])


def test_five_styles_at_three_durations_start_lying_and_end_standing():
    cs = build_curves(list(STYLES), {}, [2.5, 5.1, 7.6])
    assert len(STYLES) == 5 and len(cs) == 15  # 003 §5.5: 5 authored x (2.5, 5.1, 7.6 s)
    assert sorted({c.duration for c in cs}) == [2.5, 5.1, 7.6]
    for c in cs:
        name = c.name.split("@")[0]
        start = SUPINE if STYLES_DEG[name][3] == "supine" else PRONE
        np.testing.assert_allclose(c(0.0), deg(start), atol=1e-9)  # docs/getup.md: where each starts
        np.testing.assert_allclose(c(c.duration), deg(STAND), atol=1e-9)  # ... and ends, at t = T
        np.testing.assert_allclose(c(c.duration + 3.0), deg(STAND), atol=1e-9)  # eq 1: s clamped at 1
        mid = c(0.5 * c.duration)
        assert 0.3 < mid[0] < 1.0  # half-way up, not a straight line from lying to standing
    # the same curve at 2.5 s is the 7.6 s one time-compressed
    fast = {c.name: c for c in cs}["situp_roll@2.5s"]
    slow = {c.name: c for c in cs}["situp_roll@7.6s"]
    np.testing.assert_allclose(fast(1.0), slow(7.6 / 2.5), atol=1e-12)


def test_styles_differ_where_the_strategies_do():
    c = {x.name: x for x in build_curves(list(STYLES), {}, None)}
    t = np.linspace(0.0, c["situp_roll"].duration, 50)
    # only the supine roll-over passes through lying on a side (θx far from 90°)
    assert np.min(c["pushup_supine"](t)[:, 1]) < math.radians(45)  # control point 30°, the spline 42°
    assert np.all(np.abs(c["pushup_prone"](t)[:, 1] - math.pi / 2) < 1e-9)
    # the sit-up brings the torso upright (θz ≈ 90°) while h is still at sitting height
    up = c["situp_roll"](t)
    k = int(np.argmin(np.abs(up[:, 2] - math.pi / 2)))
    assert up[k, 0] < 0.8


def test_the_task_trains_on_them_by_default_and_they_are_selectable():
    from toolkit import plugins
    from toolkit.config import compose, validate

    task = plugins.load("task", "getup")(validate(compose(["task=getup", "action=raw"])))
    names = [c.name for c in task.curve_set(1.0)]
    assert len(names) == 4 + 15 and "prone_squat@5.1s" in names
    task = plugins.load("task", "getup")(validate(compose(
        ["task=getup", "action=raw", "task.curves=[faceup,situp_roll]", "task.eval_curve=faceup",
         "task.authored_durations=[]"])))
    assert [(c.name, c.duration) for c in task.curve_set(1.0)][1] == ("situp_roll", 5.1)
    with pytest.raises(JtError, match="unknown curve or style 'cartwheel'.*situp_roll"):
        validate(compose(["task=getup", "action=raw", "task.curves=[facedown,cartwheel]"]))
