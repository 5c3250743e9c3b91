"""Rewards: r_G of 000 eqs 13-14 (analytic values) and DeepMimic's r_I against the clip itself."""

from __future__ import annotations

import math

import numpy as np
import pytest

from runup_helpers import FOSBURY_TARGET, STRADDLE_TARGET, make_env


def test_goal_reward_analytic_values():
    from jt_tasks.runup.reward import goal_reward, goal_targets

    hj = goal_targets("highjump", FOSBURY_TARGET)
    assert hj == {"omega_x": -3.0, "omega_z": 1.0, "v_z": -2.4, "omega_y": 3.0}  # omega_y fixed (000 §6.1.1)
    at = {"omega_x": -3.0, "omega_y": 3.0, "omega_z": 1.0, "v_z": -2.4}
    assert goal_reward("highjump", at, hj) == 1.0
    # eq 13: exp(-1/3 * |dω|_1 - 0.7 dv_z^2)
    off = dict(at, omega_x=-2.7, omega_y=2.4, v_z=-1.9)
    assert goal_reward("highjump", off, hj) == pytest.approx(math.exp(-(0.3 + 0.6) / 3 - 0.7 * 0.25), rel=1e-12)
    # eq 14 ignores v_z entirely and compares all three ω components
    ob = goal_targets("obstacle", STRADDLE_TARGET)
    assert ob == STRADDLE_TARGET
    assert goal_reward("obstacle", {**STRADDLE_TARGET, "v_z": 5.0}, ob) == 1.0
    got = {"omega_x": 0.3, "omega_y": -0.6, "omega_z": 1.9, "v_z": 0.0}
    assert goal_reward("obstacle", got, ob) == pytest.approx(math.exp(-1.8 / 3), rel=1e-12)
    # falls as the features move away
    vals = [goal_reward("highjump", dict(at, v_z=-2.4 + d, omega_z=1.0 - d), hj) for d in (0.0, 0.1, 0.5, 1.0, 2.0)]
    assert all(a > b for a, b in zip(vals, vals[1:]))
    from toolkit.errors import JtError

    with pytest.raises(JtError):
        goal_targets("highjump", {"omega_x": 0.0})
    with pytest.raises(JtError):
        goal_targets("longjump", STRADDLE_TARGET)


def test_goal_reward_is_one_on_a_simulated_state_with_the_target_features():
    """takeoff/state.py builds a state with imposed features; the env measures them back."""
    from jt_tasks.takeoff.state import takeoff_state
    from jt_tasks.runup.reward import goal_reward, measure

    e = make_env(seed=0)
    try:
        for kind, target, omega_y in (("highjump", FOSBURY_TARGET, 3.0), ("obstacle", STRADDLE_TARGET, None)):
            from jt_tasks.runup.reward import goal_targets

            tg = goal_targets(kind, target)
            st = takeoff_state(dict(target), "run", "right", omega_y)
            e.sim.reset(st.q + np.r_[0.0, 0.5, 0.0, np.zeros(len(st.q) - 3)], st.qd)  # in the air
            got = measure(*e.sim.state())
            assert goal_reward(kind, got, tg) == pytest.approx(1.0, abs=1e-9)
            q, qd = e.sim.state()
            qd[3] += 0.6  # world omega_x: the facing frame's x is the heading, here world +x
            e.sim.reset(q, qd)
            assert goal_reward(kind, measure(*e.sim.state()), tg) == pytest.approx(math.exp(-0.2), rel=1e-6)
    finally:
        e.close()


def _clip_frame_state(env, k):
    """Frame ``k`` of the run clip straight from toolkit.motion (positions, finite-difference velocities)."""
    clip = env.ref.clip
    vel = clip.velocities()
    q = np.concatenate([clip.root_pos[k] + [0.0, env.ref.ground_offset, 0.0], clip.root_rot[k], clip.joints[k]])
    qd = np.concatenate([vel.root_lin[k], vel.root_ang[k], vel.joints[k]])
    return q, qd


def test_imitation_reward_is_one_on_the_clip_and_drops_as_printed():
    """The simulated state set to a frame of the clip (an outside reference) scores r_I ~ 1."""
    e = make_env(seed=0)
    try:
        clip = e.ref.clip
        for k in (3, 9, 17):
            q, qd = _clip_frame_state(e, k)
            e.reset(options={"time": float(clip.times[k])})
            e.sim.reset(q, qd)
            terms = e.imitation()
            assert terms["pose"] > 0.999 and terms["ee"] > 0.999 and terms["com"] > 0.999, terms
            # velocities: the clip's frame differences vs the env's 1/120 s differences of the slerped
            # pose agree to second order only (up to 0.7 rad/s at the ankles of this clip)
            assert terms["vel"] > 0.9, terms
            assert terms["imitation"] > 0.99
        # one knee off by 0.3 rad: r_pose = exp(-2 * 0.3^2) exactly (Peng et al. 2018 §6)
        knee = 7 + e.skeleton.q_slices["right_knee"].start
        q2 = q.copy()
        q2[knee] += 0.3
        e.sim.reset(q2, qd)
        terms2 = e.imitation()
        e.sim.reset(q, qd)
        base = e.imitation()
        assert terms2["pose"] / base["pose"] == pytest.approx(math.exp(-2 * 0.09), rel=1e-3)
        assert terms2["ee"] < base["ee"] and terms2["com"] <= base["com"] + 1e-12
        # the whole character 10 cm to the side: only the world CoM term moves, by exp(-10 * 0.01)
        q3 = q.copy()
        q3[2] += 0.1
        e.sim.reset(q3, qd)
        terms3 = e.imitation()
        assert terms3["com"] / base["com"] == pytest.approx(math.exp(-10 * 0.01), rel=1e-3)
        assert terms3["pose"] == pytest.approx(base["pose"]) and terms3["ee"] == pytest.approx(base["ee"])
    finally:
        e.close()
