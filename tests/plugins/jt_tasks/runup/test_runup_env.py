"""The run-up environment: gymnasium API, RSI, early termination, the take-off instant, final info."""

from __future__ import annotations

import math

import numpy as np
import pytest

from runup_helpers import STRADDLE_TARGET, make_env


@pytest.fixture(scope="module")
def env():
    e = make_env(seed=0)
    yield e
    e.close()


def test_env_checker_highjump_and_obstacle():
    from toolkit.rl.gym_check import check_gym_env

    for kw in ({}, {"kind": "obstacle", "target": dict(STRADDLE_TARGET)}):
        e = make_env(seed=0, n_strides=1, **kw)
        try:
            check_gym_env(e)
            obs, _ = e.reset(seed=3)
            assert obs.shape == e.observation_space.shape and np.all(np.isfinite(obs))
            assert e.action_space.shape == (28,)
        finally:
            e.close()


def test_rsi_is_seeded_and_spreads_over_the_cycle(env):
    starts = [env.reset(seed=s)[1]["start_time"] for s in range(12)]
    again = [env.reset(seed=s)[1]["start_time"] for s in range(12)]
    assert starts == again  # same seed, same phase
    assert len(set(starts)) == len(starts)  # different seeds, different phases
    period = env.ref.period
    assert all(0.0 <= t < period + 1e-9 for t in starts)
    assert max(starts) - min(starts) > 0.5 * period
    # the initial state is the reference state at that phase (on the 600 Hz grid)
    env.reset(seed=5)
    q, qd = env.sim.state()
    ref = env.ref.at(env.j0)
    np.testing.assert_allclose(q[3:], ref.q[3:], atol=1e-9)
    np.testing.assert_allclose(qd, ref.qd, atol=1e-9)
    assert env.t0 * env.sim_hz == pytest.approx(round(env.t0 * env.sim_hz), abs=1e-9)


def test_takeoff_schedule_is_n_strides_of_take_off_foot_mid_supports():
    e = make_env(seed=0, n_strides=2)
    try:
        T, gap = e.ref.period, 1.0 / e.control_hz
        for t0 in np.linspace(-0.3, 1.7, 17):
            _, info = e.reset(options={"time": float(t0)})
            t_end, start = info["takeoff_time"], info["start_time"]
            k = (t_end - e.ref.t_mid) / T
            assert k == pytest.approx(round(k), abs=1e-9)  # a mid-support of the take-off foot
            assert start + gap + T < t_end <= start + gap + 2 * T + 1e-9  # the 2nd one after the start
            assert info["n_steps"] == math.ceil(round((t_end - start) * e.sim_hz) / e.substeps)
    finally:
        e.close()


def test_reference_mid_support_is_where_takeoff_py_puts_it():
    """Outside reference: the take-off foot is lowest (in support) at the take-off instant."""
    from jt_tasks.takeoff.state import FOOT_LINKS

    e = make_env(seed=0)
    try:
        ts = e.ref.t_mid + np.linspace(-0.4, 0.4, 33)
        feet = [e.ref.lowest_point(e.ref.state(t)[0], FOOT_LINKS["right"]) for t in ts]
        assert feet[16] == pytest.approx(e.spec_.foot_clearance, abs=1e-9)  # placed at the take-off
        assert feet[16] < min(feet[:6] + feet[-6:]) - 0.05  # the foot is up half a cycle away
    finally:
        e.close()


def test_episode_ends_at_the_take_off_instant_with_every_reward_part():
    e = make_env(seed=0, n_strides=1)
    try:
        _, info0 = e.reset(options={"time": e.ref.t_mid - 0.25})
        zero = np.zeros(e.action_space.shape, np.float32)
        rewards, info, done = [], {}, False
        while not done:
            _, r, term, trunc, info = e.step(zero)
            rewards.append(r)
            done = term or trunc
        assert term and not trunc
        assert info["took_off"] == 1.0 and info["fell"] == 0.0 and info["reason"] == "take-off"
        assert len(rewards) == info0["n_steps"] == info["steps"]
        assert e.clip_time == pytest.approx(info0["takeoff_time"], abs=0.5 / e.sim_hz)
        assert e.ref.phase(e.clip_time) * e.ref.period == pytest.approx(e.ref.t_mid, abs=0.5 / e.sim_hz)
        for k in ("r_imitation_mean", "r_pose_mean", "r_vel_mean", "r_ee_mean", "r_com_mean", "r_goal",
                  "takeoff_omega_x", "takeoff_omega_y", "takeoff_omega_z", "takeoff_v_z",
                  "target_omega_x", "target_omega_y", "target_omega_z", "target_v_z"):
            assert k in info and math.isfinite(info[k]), k
        assert info["target_omega_y"] == 3.0  # 000 §6.1.1
        # the final reward: w_I r_I of the last step plus the terminal goal part
        spec = e.spec_
        r_i = [t["imitation"] for t in e.terms_log]
        assert info["r_imitation_mean"] == pytest.approx(np.mean(r_i))
        np.testing.assert_allclose(rewards[:-1], spec.w_imitation * np.array(r_i[:-1]))
        assert rewards[-1] == pytest.approx(spec.w_imitation * r_i[-1] + spec.w_goal * len(rewards) * info["r_goal"])
        # r_G is eq 13 of the achieved features, which are those of the final simulated state
        from jt_tasks.runup.reward import goal_reward, measure

        q, qd = e.sim.state()
        got = measure(q, qd)
        assert got["omega_x"] == pytest.approx(info["takeoff_omega_x"])
        assert got["v_z"] == pytest.approx(info["takeoff_v_z"])
        assert info["r_goal"] == pytest.approx(goal_reward("highjump", got, e.targets))
        with pytest.raises(RuntimeError):
            e.step(zero)
    finally:
        e.close()


def test_a_fall_terminates_early_without_the_goal(env):
    from toolkit.motion import rotations as rot

    env.reset(seed=0)
    q, qd = env.sim.state()
    q[1] = 0.25  # root low, body lying on its side: the torso and head touch the ground
    q[3:7] = rot.quat_from_axis_angle(np.array([1.0, 0.0, 0.0]), math.pi / 2)
    env.sim.reset(q, np.zeros_like(qd))
    _, r, term, trunc, info = env.step(np.zeros(env.action_space.shape, np.float32))
    assert term and not trunc
    assert info["fell"] == 1.0 and info["took_off"] == 0.0 and info["reason"] == "fell"
    assert info["r_goal"] == 0.0 and info["steps"] == 1.0
    assert r == pytest.approx(env.spec_.w_imitation * env.terms_log[-1]["imitation"])


def test_same_seed_same_episode():
    a, b = make_env(seed=4, n_strides=1), make_env(seed=4, n_strides=1)
    try:
        rng = np.random.default_rng(0)
        oa, _ = a.reset(seed=9)
        ob, _ = b.reset(seed=9)
        np.testing.assert_array_equal(oa, ob)
        for _ in range(5):
            act = rng.uniform(a.action_space.low, a.action_space.high).astype(np.float32) * 0.2
            ra, rb = a.step(act), b.step(act)
            np.testing.assert_array_equal(ra[0], rb[0])
            assert ra[1] == rb[1]
            if ra[2]:
                break
    finally:
        a.close()
        b.close()


def test_the_control_rate_is_the_simulators():
    """``sim.control_hz`` drives the run-up as it drives getup and spacetime (one value, one place)."""
    from toolkit import plugins
    from toolkit.config import compose

    for hz, substeps in ((30, 20), (60, 10)):
        e = plugins.load("task", "runup")(compose(["task=runup", f"sim.control_hz={hz}"])).make_env(seed=0)
        try:
            assert e.control_hz == hz and e.substeps == substeps
        finally:
            e.close()
