"""Clip starts inside the clip (task.rsi), perturbed clip starts (task.start_noise, the reset's
``noise``) and the stage-1 evaluation from perturbed clip starts (jt_tasks.getup.stage1)."""

from __future__ import annotations

import numpy as np
import pytest

from toolkit.errors import JtError


def make_task(*overrides: str):
    from toolkit import plugins
    from toolkit.config import compose, validate

    cfg = validate(compose(["task=getup", "action=raw", "task.n_fallen=0", "task.terrain=null", "~curriculum",
                            "task.eval_regions=[flat]", *overrides]))
    return plugins.load("task", "getup")(cfg)


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


class _Still:
    """A policy that holds every PD target at zero offset (raw actions: the rest pose)."""

    def __init__(self, n: int) -> None:
        self.n = n

    def act(self, obs: np.ndarray) -> np.ndarray:
        return np.zeros(self.n)


def test_an_untrained_policy_does_not_get_up_from_clip_starts():
    from jt_tasks.getup.stage1 import clip_start_success

    e = make_task("task.curves=[facedown,faceup]").make_env(None, seed=0)
    try:
        res = clip_start_success(e, _Still(e.action_space.shape[0]), 2, 0.05)
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


def test_the_clip_tracked_without_feedback_does_not_get_up():
    """What a policy must add (issue 29, jt_tasks.getup.study): PD targets set to the facedown clip's
    poses, no policy, lift the neck off the ground (> 0.3 m) but never to a standing height
    (0.8 x 1.35 m), and the character ends lying again."""
    from jt_tasks.getup.study import open_loop_clip

    from tests.plugins.jt_tasks.getup.getup_helpers import sim_groups

    o = open_loop_clip("getup_facedown", sim_groups(), t_stand=1.0)
    assert 0.3 < o["h_max"] < 0.8 * 1.35 and o["h_end"] < 0.3 and o["duration"] == pytest.approx(3.03, abs=0.01)


def test_standing_balance_gives_each_curve_its_standing_start_and_restores_t_stand():
    """``study --stand``: a policy that holds the rest pose (raw zero action, no feedback) falls from
    every standing start well before 4 s (a PD-held pose falls in ~2 s, docs/getup.md), and the
    measurement leaves the env's 3 s standing phase as it found it."""
    from jt_tasks.getup.study import standing_balance

    e = make_task("task.curves=[facedown,faceup]", "task.p_standing=1", "task.p_fallen=0").make_env(None, seed=0)
    try:
        rows = standing_balance(e, _Still(e.action_space.shape[0]), 4.0)
        assert e.spec_.t_stand == 3.0
    finally:
        e.close()
    assert [r["curve"] for r in rows] == ["facedown", "faceup"] and all(r["of"] == 120 for r in rows)
    assert all(10 < r["steps"] < 120 and r["reason"] != "time limit" for r in rows)


@pytest.mark.parametrize("argv,match", [
    (["RUN", "--stand", "0"], "--stand=0.0: the seconds of standing must be a finite number > 0"),
    (["RUN", "--stand", "nan"], "--stand=nan"),
    (["/no/such/ppo.h5", "--stand", "10"], "no such file"),
    (["RUN", "--at", "0.5", "1.0"], "--at=1.0: a clip start is a fraction of the clip in [0, 1)"),
])
def test_study_refuses_a_bad_value_in_one_line_with_exit_2(argv, match, capsys):
    from jt_tasks.getup.study import main

    with pytest.raises(SystemExit) as e:
        main(argv)
    err = capsys.readouterr().err
    assert e.value.code == 2 and match in err and len(err.strip().splitlines()) == 1


def test_policy_starts_at_chosen_fractions_say_what_a_success_needs():
    """``study --at``: episodes from the clip at the given fractions, each with the control steps a
    success lasts from there; the rest-pose policy lasts fewer than that from every one."""
    from jt_tasks.getup.study import policy_starts

    e = make_task("task.curves=[facedown,faceup]").make_env(None, seed=0)
    try:
        rows = policy_starts(e, _Still(e.action_space.shape[0]), curves=("facedown",), fractions=(0.8,))
    finally:
        e.close()
    assert [r["start"] for r in rows] == ["clip at 80%", "standing"]
    assert rows[0]["needs"] == round((0.2 * e.curves[0].duration + 3.0) * 30) and rows[0]["steps"] < rows[0]["needs"]
