"""The centre of mass by the model's forward kinematics (``toolkit.dynamics.com``) equals PyBullet's
mass-weighted mean of its link centres of mass (with forward kinematics computed), on every
character PyBullet can hold, floating and fixed base, at random states."""

from __future__ import annotations

import numpy as np
import pytest
from dynamics_worlds import SIMULABLE, state_in_limits


@pytest.mark.parametrize("fixed", [False, True], ids=["floating", "fixed"])
@pytest.mark.parametrize("name", SIMULABLE)
def test_com_equals_pybullet(worlds, name, fixed):
    import pybullet as pb

    from jt_bullet.body import BulletBody
    from toolkit.dynamics.com import CenterOfMass

    w = worlds(name, fixed)
    body, kw = w.character.body_id, {"physicsClientId": w.client}
    io = BulletBody(w.client, body, w.model)
    n = pb.getNumJoints(body, **kw)
    masses = np.array([pb.getDynamicsInfo(body, i, **kw)[0] for i in range(-1, n)])
    com = CenterOfMass(w.model)
    rng = np.random.default_rng(11)
    for _ in range(5):
        q, qd = state_in_limits(w, rng)
        io.reset(q, qd)
        q_now, _ = io.read()
        base = pb.getBasePositionAndOrientation(body, **kw)[0]
        links = pb.getLinkStates(body, list(range(n)), computeForwardKinematics=True, **kw)
        pts = np.array([base] + [s[0] for s in links])
        expected = masses @ pts / masses.sum()
        np.testing.assert_allclose(com(q_now), expected, atol=1e-9, err_msg=name)
