"""The jump environment: gymnasium API, take-off state, failure and success rules, determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import make_spec


def test_env_checker_highjump_obstacle_longjump():
    from jt_tasks.jumping.env import JumpEnv
    from jt_tasks.jumping.scene import SuiteSpec
    from toolkit.rl.gym_check import check_gym_env

    specs = [make_spec(),
             make_spec(kind="obstacle", features={"omega_x": 0.0, "omega_y": 0.0, "omega_z": 1.0},
                       omega_y=None, suite=SuiteSpec(kind="obstacle", obstacle_width=0.3)),
             make_spec(kind="obstacle", features={"omega_x": 1.0, "omega_y": -1.0, "omega_z": 0.5},
                       omega_y=None, suite=SuiteSpec(kind="obstacle", obstacle_height=0.0, obstacle_width=0.5))]
    for spec in specs:
        env = JumpEnv(spec, seed=0)
        try:
            check_gym_env(env)
            assert env.observation_space.shape[0] == env.reset(seed=1)[0].shape[0]
        finally:
            env.close()


def test_takeoff_state_has_the_imposed_features(env):
    from jt_tasks.takeoff.state import facing_velocities

    env.reset(seed=0)
    q, qd = env.sim.state()
    v, w = facing_velocities(q, qd)
    np.testing.assert_allclose(w, [-3.0, 3.0, 1.0], atol=1e-6)  # omega_y fixed at 3 rad/s (000 §6.1.1)
    assert v[2] == pytest.approx(-2.4, abs=1e-6)
    # heading along +x, take-off foot just above the ground, the other foot in the air
    foot = env.sim.aabb(env.foot_link)[0][1]
    other = env.sim.aabb(11)[0][1]
    assert foot == pytest.approx(env.spec_.foot_clearance, abs=1e-6)
    assert other > 0.03


def _teleport(env, dx):
    """Shift the character by ``dx`` (3,) and zero its velocity."""
    q, qd = env.sim.state()
    q[:3] += np.asarray(dx)
    env.sim.reset(q, np.zeros_like(qd))


def _hold(env):
    return env.skeleton.joints_to_dofs(env._q0[7:]).astype(np.float32)


def test_touching_the_wall_fails(env):
    env.reset(seed=0)
    d = env.suite.plane - 0.05  # root a few cm before the bar plane: the body is in the wall
    _teleport(env, env.suite.normal * d)
    obs, r, term, trunc, info = env.step(_hold(env))
    assert term and not trunc
    assert info["reason"] == "touched the bar"
    assert r == 0.0 and info["success"] == 0.0 and info["r_task_complete"] == 0.0


def test_a_scripted_fall_fails():
    from jt_tasks.jumping.env import JumpEnv

    env = JumpEnv(make_spec(features={"alpha": math.pi, "omega_x": 0.0, "omega_z": 0.0, "v_z": 0.0},
                            omega_y=0.0), seed=0)  # the bar behind: only a fall can end it
    try:
        env.reset(seed=0)
        zero = np.zeros(env.action_space.shape, np.float32)
        for _ in range(40):
            obs, r, term, trunc, info = env.step(zero)
            if term:
                break
        assert term and info["reason"] in ("touched the ground", "time limit")
        assert info["reason"] == "touched the ground"
        assert r == 0.0
    finally:
        env.close()


def test_landing_on_the_mat_away_from_the_wall_succeeds(env):
    env.reset(seed=0)
    s = env.suite.spec
    # the root 1.6 m past the bar plane, above the mat (top at mat_height), upright, at rest
    _teleport(env, env.suite.normal * (env.suite.far + 1.5) + np.array([0, s.mat_height + 0.05, 0]))
    for _ in range(10):
        obs, r, term, trunc, info = env.step(_hold(env))
        if term:
            break
    assert term and info["success"] == 1.0, info
    terms = [info[k] for k in ("r_task_complete", "r_root_rotation", "r_safety", "r_naturalness")]
    assert r == pytest.approx(math.prod(terms)) and r > 0.5
    assert info["r_naturalness"] == 1.0  # raw actions carry no penalty


def test_landing_too_close_to_the_wall_is_not_a_success(env):
    env.reset(seed=0)
    s = env.suite.spec
    # feet on the mat but the body within 20 cm of the wall: the episode goes on (then times out)
    _teleport(env, env.suite.normal * (env.suite.far + 0.12) + np.array([0, s.mat_height + 0.02, 0]))
    obs, r, term, trunc, info = env.step(_hold(env))
    assert env.landed or term
    assert not (term and info.get("success") == 1.0)


def test_rollout_with_fixed_actions_is_deterministic():
    from jt_tasks.jumping.env import JumpEnv

    rng = np.random.default_rng(3)
    outs = []
    for _ in range(2):
        env = JumpEnv(make_spec(), seed=0)
        lo, hi = env.action_space.low, env.action_space.high
        acts = [rng.uniform(lo, hi).astype(np.float32) for _ in range(6)] if not outs else acts
        env.reset(seed=0)
        seq = []
        for a in acts:
            o, r, term, trunc, info = env.step(a)
            seq.append((o.copy(), r))
            if term:
                break
        outs.append(seq)
        env.close()
    assert len(outs[0]) == len(outs[1])
    for (o1, r1), (o2, r2) in zip(*outs):
        np.testing.assert_array_equal(o1, o2)
        assert r1 == r2


def test_control_rate_maps_onto_substeps(env):
    env.control_hz = 10.0
    assert env.substeps == 60
    env.control_hz = 30.0
    assert env.substeps == 20
    env.control_hz = 10.4  # a curriculum value between: the nearest whole number of substeps
    assert env.substeps == 58
    env.bar_height = 0.7
    env.reset(seed=0)
    assert env.suite.barrier_height == pytest.approx(0.7)


@pytest.mark.parametrize("v_y, cleared", [(None, False), (2.06, True)])
def test_holding_the_takeoff_pose_clears_a_low_bar_only_with_the_jumping_intention(v_y, cleared):
    """Without the vertical speed the body runs into the 0.5 m wall whatever the pose; with it,
    simply holding the take-off pose carries the CoM over the bar plane (what makes the
    curriculum's first level learnable)."""
    from jt_tasks.jumping.env import JumpEnv

    env = JumpEnv(make_spec(v_y=v_y), seed=0)
    try:
        env.reset(seed=0)
        hold = env.skeleton.joints_to_dofs(env._q0[7:]).astype(np.float32)
        done, info = False, {}
        while not done:
            _, _, done, _, info = env.step(hold)
        assert bool(info["crossed"]) is cleared
        if not cleared:
            assert info["reason"] == "touched the bar"
    finally:
        env.close()


def _hold_to_the_end(env) -> tuple[dict, list]:
    """Hold the take-off pose over a 20 cm bar to the end; the info and the CoM ``(past, along
    offset)`` per step."""
    env.bar_height = 0.2
    env.reset(seed=0)
    hold = env.skeleton.joints_to_dofs(env._q0[7:]).astype(np.float32)
    done, info, path = False, {}, []
    while not done:
        _, _, done, _, info = env.step(hold)
        com = env._com_and_links()[0]
        path.append((float(env.suite.past(com)), float(env.suite.along_offset(com))))
    return info, path


def test_the_wall_stands_where_the_jump_crosses_its_plane():
    """The wall and the mat are centred where the take-off velocity crosses the bar plane; a
    hold-pose jump crosses within 0.6 m of that centre (1.6 m from the foot of the perpendicular)."""
    from jt_tasks.jumping.env import JumpEnv

    env = JumpEnv(make_spec(features={"alpha": 0.01, "omega_x": -2.5, "omega_z": 0.34, "v_z": -1.17},
                            v_y=2.06), seed=0)
    try:
        assert env.suite.spec.centre_along > 1.5
        info, path = _hold_to_the_end(env)
        assert info["crossed"] and info["success"]
        at = np.array(path)[np.argmax(np.array(path)[:, 0] >= 0)]
        assert abs(at[1]) < 0.6
    finally:
        env.close()


def test_passing_round_the_end_of_the_wall_is_no_crossing():
    from jt_tasks.jumping.env import JumpEnv

    env = JumpEnv(make_spec(features={"alpha": 0.01, "omega_x": -2.5, "omega_z": 0.34, "v_z": -1.17},
                            v_y=2.06), seed=0)
    try:
        env.suite.update(centre_along=env.suite.spec.centre_along + 3.0)  # the wall ends 1 m short of the jump
        info, _ = _hold_to_the_end(env)
        assert info["reason"] == "passed beside the bar" and not info["crossed"] and not info["success"]
        assert np.isnan(info["feature_angle"])
    finally:
        env.close()
