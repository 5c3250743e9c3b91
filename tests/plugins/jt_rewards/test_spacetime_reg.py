"""spacetime_reg (002 §3.3 eqs 7-8): the regulariser with β's from a reference clip's statistics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from jt_rewards.spacetime_reg import SpacetimeReg, clip_betas, clip_statistics, upper_bound
from toolkit.errors import JtError
from toolkit.testing.reward import RewardTermContract

MASSES = np.array([6.0, 14.0, 2.0] + [3.0] * 13)  # 16 bodies, M = 61 kg
STILL = {"link_vel": np.zeros((16, 3)), "link_acc": np.zeros((16, 3)), "masses": MASSES,
         "joint_acc": np.zeros(28), "clip": "run"}
B_E, B_C, B_B, B_J = clip_betas("run")
UP = dict(STILL, link_vel=np.tile([0.0, 1.0, 0.0], (16, 1)))  # everything moves up at 1 m/s: E = ½ M
LIFT = dict(STILL, link_acc=np.tile([0.0, 2.0, 0.0], (16, 1)))  # a shared vertical acceleration of 2


class TestSpacetimeReg(RewardTermContract):
    cls, entry, record = SpacetimeReg, "spacetime_reg", STILL
    required = ("link_vel", "link_acc", "masses", "joint_acc", "clip")
    cases = [({}, STILL, 1.0), ({"clip": "run"}, {k: v for k, v in STILL.items() if k != "clip"}, 1.0),
             ({}, UP, math.exp(-(0.5 * MASSES.sum() / B_E) / 4)),
             ({}, LIFT, math.exp(-(2.0 / B_C) / 4)),  # bodies move with the CoM: no relative term
             ({"e_scale": 8.0}, UP, math.exp(-(0.5 * MASSES.sum() / (B_E / 2)) / 4))]


def test_upper_bound_is_the_upper_fence_or_the_max():
    x = np.array([1.0, 2, 3, 4, 5, 6, 7, 8, 100])  # Q1 3, Q3 7: fence 13 < max 100
    assert upper_bound(x) == pytest.approx(13.0)
    assert upper_bound(np.array([1.0, 2, 3, 4])) == pytest.approx(4.0)  # fence 6.25 > max 4


def test_betas_follow_the_clip_run_above_walk():
    s = clip_statistics("walk")
    assert s["body_acc"].shape[1] == 16 and s["joint_acc"].shape[1] == 12
    run, walk = clip_betas("run"), clip_betas("walk")
    assert run[0] > 5 * walk[0]  # run's energy bound (~80 J) far above walk's (~7 J) x 16 each
    assert (run[3] > walk[3]).sum() >= 8 and np.all(np.asarray(run[3]) >= 0.1 * 400)


def test_joint_accelerations_lower_the_reward_monotonically():
    term = SpacetimeReg()
    rs = [term(dict(STILL, joint_acc=np.full(28, a))) for a in (0.0, 1e3, 1e4, 1e5)]
    assert rs[0] == 1.0 and all(a > b for a, b in zip(rs, rs[1:])) and rs[-1] > 0


def test_unknown_clip_is_one_line_error():
    with pytest.raises(JtError, match="no such clip") as e:
        SpacetimeReg({"clip": "moonwalk"})(STILL)
    assert "\n" not in str(e.value)
