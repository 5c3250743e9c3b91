"""Clip starts inside the clip (task.rsi), perturbed clip starts (task.start_noise, the reset's
``noise``) and the stage-1 evaluation from perturbed clip starts (jt_tasks.getup.stage1)."""

from __future__ import annotations

import numpy as np
import pytest

from toolkit.errors import JtError

from tests.plugins.jt_tasks.getup.getup_helpers import Still, make_task


@pytest.fixture(scope="module")
def env():
    e = make_task("task.rsi=1.0", "task.p_standing=0", "task.p_fallen=0").make_env(None, seed=0)
    yield e
    e.close()


def test_a_start_inside_the_clip_is_the_clips_state_with_the_curve_at_that_time(env):
    from jt_tasks.getup.curves import clip_feature_track

    env.reset(seed=0, options={"kind": "clip", "curve": "facedown", "at": 1.5})
    assert env.t == pytest.approx(1.5) and env.start_time == pytest.approx(1.5)
    # the measured features are the clip's at 1.5 s (both on the ground frame of that frame)
    times, feats = clip_feature_track("getup_facedown")
    want = feats[int(np.argmin(np.abs(times - times[0] - 1.5)))]
    np.testing.assert_allclose(env.measure()["features"], want, atol=0.03)
    # the episode still ends at T + 3 s on the curve's clock
    assert env.watch.time_limit == pytest.approx(env.curve.duration + 3.0 - 1.5)
    q, qd = env.sim.state()
    assert np.linalg.norm(qd) > 0.1  # the clip's velocities, not a standstill


def test_rsi_draws_start_times_over_the_clip_and_seeds_them(env):
    times = [env.reset(seed=s)[1].get("start_time", 0.0) for s in range(12)]
    again = [env.reset(seed=s)[1].get("start_time", 0.0) for s in range(12)]
    assert times == again
    assert min(times) > 0.0 and max(times) < 3.8 and np.std(times) > 0.4
    info = {}
    done = False
    while not done:
        _, _, te, tr, info = env.step(np.zeros(env.action_space.shape, np.float32))
        done = te or tr
    assert info["start_time"] == pytest.approx(env.start_time)  # the history leaves these out


def test_default_clip_starts_draw_nothing_new():
    """rsi = start_noise = 0 (003's starts): no start_time, the clip's first pose."""
    e = make_task().make_env(None, seed=0)
    try:
        _, info = e.reset(seed=0, options={"kind": "clip", "curve": "faceup"})
        assert "start_time" not in info and e.t == 0.0
    finally:
        e.close()


def test_noise_perturbs_the_start_seeded_and_keeps_it_on_the_ground(env):
    from jt_tasks.getup.ground import CLEARANCE, lowest_point

    env.reset(seed=0, options={"kind": "clip", "curve": "faceup", "at": 0.0})
    q0 = env.sim.state()[0].copy()
    env.reset(seed=0, options={"kind": "clip", "curve": "faceup", "at": 0.0, "noise": 0.05, "noise_seed": 7})
    q1 = env.sim.state()[0].copy()
    env.reset(seed=5, options={"kind": "clip", "curve": "faceup", "at": 0.0, "noise": 0.05, "noise_seed": 7})
    q2 = env.sim.state()[0].copy()
    env.reset(seed=0, options={"kind": "clip", "curve": "faceup", "at": 0.0, "noise": 0.05, "noise_seed": 8})
    q3 = env.sim.state()[0].copy()
    assert 1e-3 < np.abs(q1[7:] - q0[7:]).max() < 0.1
    np.testing.assert_allclose(q1, q2)  # the noise seed alone decides the perturbation
    assert np.abs(q3 - q1).max() > 1e-3
    assert lowest_point(q1) == pytest.approx(CLEARANCE, abs=1e-6)


def test_clip_start_options_cycle_the_clip_curves_with_their_own_seeds():
    from jt_tasks.getup.curves import build_curves
    from jt_tasks.getup.stage1 import clip_start_options

    curves = build_curves(["facedown", "situp_roll", "faceup"], {}, None)
    opts = clip_start_options(curves, 5, 0.05, seed=3)
    assert [o["curve"] for o in opts] == ["facedown", "faceup", "facedown", "faceup", "facedown"]
    assert [o["noise_seed"] for o in opts] == [3, 4, 5, 6, 7] and all(o["kind"] == "clip" for o in opts)
    with pytest.raises(ValueError, match="reference curve"):
        clip_start_options(build_curves(["situp_roll"], {}, None), 2, 0.05)


def test_an_untrained_policy_does_not_get_up_from_clip_starts():
    from jt_tasks.getup.stage1 import clip_start_success

    e = make_task("task.curves=[facedown,faceup]").make_env(None, seed=0)
    try:
        res = clip_start_success(e, Still(e.action_space.shape[0]), 2, 0.05)
    finally:
        e.close()
    assert res["success"] == 0.0 and res["got_up"] == 0.0 and len(res["infos"]) == 2
    assert all(i["early"] == 1.0 for i in res["infos"])


@pytest.mark.parametrize("override,match", [
    ("task.rsi=1.5", "task.rsi"), ("task.start_noise=-0.1", "task.start_noise"),
    ("task.eval_clip_starts=-1", "task.eval_clip_starts"), ("task.eval_every=-2", "task.eval_every"),
    ("task.curves=[situp_roll] task.eval_curve=situp_roll", "need a reference curve"),
    # the reverse curriculum over starts inside the clip (test_getup_reverse.py)
    ("task.rsi=0.5 task.rsi_from=1.0", "task.rsi_from"), ("task.rsi=0.5 task.rsi_step=-0.1", "task.rsi_step"),
    ("task.rsi=0.5 task.rsi_success=0", "task.rsi_success"), ("task.rsi=0.5 task.rsi_episodes=0", "task.rsi_episodes"),
    ("task.rsi_from=0.5", "need task.rsi > 0"), ("task.stand_pose=tpose", "task.stand_pose"),
])
def test_bad_values_are_one_line(override, match):
    with pytest.raises(JtError, match=match):
        make_task("task.eval_clip_starts=4", *override.split())
