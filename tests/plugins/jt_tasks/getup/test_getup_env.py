"""GetupEnv: gymnasium API, seeded starts, state size, reward = r_task · r_natural, early termination."""

from __future__ import annotations

import math

import numpy as np
import pytest

from toolkit.errors import JtError


@pytest.fixture(scope="module")
def task():
    from toolkit import plugins
    from toolkit.config import compose, validate

    cfg = validate(compose(["task=getup", "action=raw", "task.n_fallen=2"]))
    return plugins.load("task", "getup")(cfg)


@pytest.fixture(scope="module")
def env(task):
    e = task.make_env(None, seed=0)
    yield e
    e.close()


def test_gymnasium_checker_and_state_layout(task):
    from toolkit.rl.gym_check import check_gym_env

    e = task.make_env(None, seed=0)
    try:
        check_gym_env(e)
        obs, _ = e.reset(seed=3)
        # 003 §3.3 with the base + 15 PyBullet links: q 64, p 48, ω 48, v 48, w 3, height map 25,
        # targets 12, previous action 28 (action=raw)
        n = e.n_links + 1
        assert n == 16 and obs.shape == (4 * n + 3 * 3 * n + 3 + 25 + 12 + 28,) and np.all(np.isfinite(obs))
    finally:
        e.close()


def test_starts_are_seeded_and_of_every_kind(env):
    a = [env.reset(seed=s)[1] for s in range(20)]
    b = [env.reset(seed=s)[1] for s in range(20)]
    assert a == b
    assert {i["start_kind"] for i in a} == {0.0, 1.0, 2.0}
    _, info = env.reset(options={"kind": "clip", "curve": "faceup"})
    h, tx, tz = env.measure()["features"]
    assert env.curve.name == "faceup" and math.degrees(tz) < 20 and h < 0.3  # the clip's first pose, supine
    assert env.head_down_at_start
    _, info = env.reset(options={"kind": "standing", "curve": "facedown"})
    assert env.t == pytest.approx(env.curve.duration)  # s = 1 from the start
    np.testing.assert_allclose(env.targets(env.t), env.curve.end)


def test_fallen_start_takes_a_matching_curve(env):
    for i, st in enumerate(env.spec_.fallen):
        env.reset(seed=i, options={"kind": "fallen", "fallen": i})
        _, tx, tz = env.measure()["features"]
        d = np.abs(env.curve.start[1:] - [tx, tz])
        best = np.abs(env.curve_starts[:, 1:] - [tx, tz]).sum(axis=1).min()
        assert np.all(d <= math.radians(30)) or d.sum() == pytest.approx(best)


def test_reward_is_the_product_and_episode_ends_with_info(env):
    env.reset(seed=0, options={"kind": "clip", "curve": "facedown"})
    done, info = False, {}
    while not done:
        _, r, te, tr, info = env.step(np.zeros(env.action_space.shape, np.float32))
        row = env.log[-1]
        terms = [row[k] for k in ("r_getup_height", "r_getup_torso", "r_getup_velocity", "r_getup_pose")]
        assert row["r_task"] == pytest.approx(math.prod(terms))
        assert r == pytest.approx(row["r_task"] * row["r_naturalness"])
        done = te or tr
    assert info["reason"] in ("r_task < 0.1", "head on the floor", "time limit")
    if te:  # early termination needs the condition sustained > 300 ms (> 9 steps of 1/30 s)
        key = "r_task" if info["reason"] == "r_task < 0.1" else "head_contact"
        tail = [row[key] for row in env.log[-10:]]
        assert all(v < 0.1 for v in tail) if key == "r_task" else all(v == 1.0 for v in tail)
    assert 0.0 <= info["task_return_rate"] <= 1.0 and info["success"] in (0.0, 1.0)


def test_the_early_termination_reason_names_the_configured_threshold():
    from toolkit import plugins
    from toolkit.config import compose, validate

    cfg = validate(compose(["task=getup", "action=raw", "task.n_fallen=2", "task.r_task_min=0.99"]))
    e = plugins.load("task", "getup")(cfg).make_env(None, seed=0)
    try:
        e.reset(seed=0, options={"kind": "clip", "curve": "facedown"})
        done, info = False, {}
        while not done:
            _, _, te, tr, info = e.step(np.zeros(e.action_space.shape, np.float32))
            done = te or tr
        assert te and info["reason"] == "r_task < 0.99"  # not the default's "r_task < 0.1"
        assert all(row["r_task"] < 0.99 for row in e.log[-10:])
    finally:
        e.close()


@pytest.mark.parametrize("override, match", [
    ("task.curves=[nope]", "unknown curve"),
    ("task.fallen_styles=[sideways]", "fallen_styles"),
    ("task.eval_episodes=0", "eval_episodes"),
    ("+task.authored={x: {h: [1, 2], theta_x: [1], theta_z: [1], duration: 2}}", "control points"),
])
def test_bad_input_is_one_line_error(override, match):
    from toolkit.config import compose, validate

    args = ["task=getup", "action=raw", override]
    if "authored" in override:
        args = ["task=getup", "action=raw", "task.curves=[x]", "task.eval_curve=x",
                "task.authored={x: {h: [1, 2], theta_x: [1], theta_z: [1], duration: 2}}"]
    with pytest.raises(JtError, match=match) as e:
        validate(compose(args))
    assert "\n" not in str(e.value)


def test_cvae_without_a_prior_is_one_line_error():
    from toolkit.config import compose, validate

    with pytest.raises(JtError, match="needs a trained prior"):
        validate(compose(["task=getup", "action.prior="]))


NINE = "[0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.9, 1.3]"


@pytest.mark.parametrize("override, match", [
    ("curriculum.regions=[]", "one or more region names"),
    ("curriculum.successes_to_unlock=0", "must be >= 1"),
    ("curriculum.regions=[flat,lava]", "the get-up terrain's regions are flat, easy, medium, hard"),
    (f"task.authored={{my: {{h: {NINE}, theta_x: {NINE}, theta_z: {NINE}, duration: -2}}}}",
     "task.authored.my.duration=-2: must be > 0 s"),
])
def test_values_are_checked_before_the_run_opens(override, match):
    """Values refused at composition, before a run row exists (issue 30, item 3)."""
    from toolkit.config import compose

    with pytest.raises(JtError, match=match) as e:
        compose(["task=getup", "action=raw", "curriculum=terrain", override])
    assert "\n" not in str(e.value)
