"""The env's reward with the eqs 7-8 regulariser and the eq 13 mix (002 §3.3, §5.3.1; real PyBullet)."""

from __future__ import annotations

import numpy as np
import pytest

from spacetime_helpers import make_env


def steps(env, n, seed=0):
    env.reset(seed=seed, options={"phase": 0.1})
    out = []
    for _ in range(n):
        _, r, te, tr, info = env.step(np.zeros(env.action_space.shape, np.float32))
        if te:  # out of bounds (or a forbidden contact): reward 0, not a style value
            break
        out.append(r)
        if tr:
            break
    return out


def test_regulariser_is_a_factor_below_one_once_the_body_accelerates():
    env = make_env(seed=0, style=[{"name": "spacetime_reg"}])
    try:
        rs = steps(env, 4)
        assert len(rs) >= 3 and rs[0] == pytest.approx(1.0, abs=0.01)  # first step: no acceleration yet
        assert all(0.0 < r <= 1.0 for r in rs) and min(rs[1:]) < rs[0]
    finally:
        env.close()


def test_eq13_mix_blends_imitation_and_style_in_the_contact_arm():
    env_i = make_env(seed=0, termination="contact")
    env_m = make_env(seed=0, termination="contact", mix=0.6, style=[{"name": "volume", "mode": "increase"}])
    try:
        ri, rm = steps(env_i, 3), steps(env_m, 3)
        env_m.reset(seed=0, options={"phase": 0.1})
        env_m.step(np.zeros(env_m.action_space.shape, np.float32))
        q, qd = env_m.sim.state()
        style = env_m.style_reward(q, qd)
        imit = env_m.imitation()
        assert 0 < style < 1 and 0 < imit < 1
        assert rm[0] == pytest.approx(0.4 * ri[0] + 0.6 * style, rel=1e-6)
        assert not np.allclose(ri, rm)
    finally:
        env_i.close()
        env_m.close()
