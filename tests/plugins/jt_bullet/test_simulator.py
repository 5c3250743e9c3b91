"""The ``bullet`` simulator: characters, failure handling, backends, torque limits, rendering."""

from __future__ import annotations

import numpy as np
import pytest

from jt_bullet.simulator import BulletSimulator
from toolkit.errors import JtError


def make(character: str = "humanoid", spd: str = "maba", **sim) -> BulletSimulator:
    return BulletSimulator({"sim": {"name": "bullet", **sim}, "character": {"name": character},
                            "spd": {"name": spd}})


def bent_target(s: BulletSimulator, angle: float = 0.6) -> np.ndarray:
    """The current pose with every joint turned by ``angle`` (spherical: about x; revolute: into
    its URDF limits)."""
    import pybullet as pb

    q, _ = s.state()
    qt = q.copy()
    k = 7
    for j, n in zip(s.character.joint_indices, s.character.joint_dofs):
        if n == 3:
            qt[k:k + 4] = [np.sin(angle / 2), 0.0, 0.0, np.cos(angle / 2)]
            k += 4
        else:
            lo, hi = pb.getJointInfo(s.character.body_id, j, physicsClientId=s.client)[8:10]
            qt[k] = float(np.clip(-angle, lo, hi)) if lo < hi else -angle
            k += 1
    return qt


@pytest.mark.parametrize("name", ["humanoid", "laikago", "atlas", "snake36", "snake72"])
def test_each_character_holds_its_pose_at_600hz(name):
    s = make(name, sim_hz=600.0, control_hz=600.0)
    try:
        q0, _ = s.state()
        for _ in range(10):
            rec = s.step(q0)
        assert not rec["failed"], rec["reason"]
        assert rec["time"] == pytest.approx(10 / 600)
        assert rec["q"].shape == (s.model.n_q,) and rec["qd"].shape == (s.model.n_v,)
        assert np.all(np.isfinite(rec["q"])) and np.all(np.isfinite(rec["qd"]))
        assert rec["contacts"].shape == (s.n_links + 1,) and rec["contacts"].dtype == bool
        assert 0.0 < s.timers["spd_s"] < s.timers["substep_s"] and s.timers["substeps"] == 10
    finally:
        s.close()


def test_snake195_is_refused_with_a_clear_error():
    with pytest.raises(JtError, match="128"):
        make("snake195")


@pytest.mark.parametrize("spd", ["maba", "bullet"])
def test_nan_or_exploding_state_is_a_failure_not_an_exception(spd):
    s = make("humanoid", spd)
    try:
        q, qd = s.state()
        fast = qd.copy()
        fast[6:] = 1e4
        s.reset(q, fast)
        rec = s.step(q)
        assert rec["failed"] and rec["reason"].startswith("exploded")
        again = s.step(q)  # a failed episode stays failed, without simulating
        assert again["failed"] and again["time"] == rec["time"]
        bad = q.copy()
        bad[7] = np.nan
        s.reset(bad, qd)
        rec = s.step(q)
        assert rec["failed"] and ("NaN" in rec["reason"] or "non-finite" in rec["reason"])
        s.reset(q, qd)
        assert not s.step(q)["failed"]
    finally:
        s.close()


def test_absurd_gains_end_the_episode_with_a_reason():
    s = BulletSimulator({"sim": {"name": "bullet", "torque_limits": False},
                         "character": {"name": "humanoid", "kp": 1e12, "kd": -1e6},
                         "spd": {"name": "maba"}})
    try:
        qt = bent_target(s, 1.5)
        recs = [s.step(qt) for _ in range(5)]
        assert recs[-1]["failed"] and recs[-1]["reason"]
    finally:
        s.close()


def test_maba_and_df_give_the_same_trajectory():
    kw = dict(sim_hz=600.0, control_hz=120.0, root_servo={"kp": 20000.0, "kd": 2000.0})
    a, b = make("humanoid", "maba", **kw), make("humanoid", "df", **kw)
    try:
        qt = bent_target(a, 0.4)
        qt[1] += 0.05
        for _ in range(4):  # 20 substeps with contacts
            ra, rb = a.step(qt), b.step(qt)
        assert not ra["failed"] and not rb["failed"]
        assert np.max(np.abs(ra["q"] - rb["q"])) < 1e-8
        assert np.max(np.abs(ra["qd"] - rb["qd"])) < 1e-6
        assert np.max(np.abs(ra["q"] - a.character.q_init)) > 1e-3  # it did move
    finally:
        a.close()
        b.close()


def test_torque_limits_are_respected_and_reach_pybullet():
    import pybullet as pb

    from toolkit.dynamics.aba import aba
    from toolkit.dynamics.model import Data

    s = make("humanoid", sim_hz=600.0, control_hz=600.0, ground=False,  # in the air, no contacts
             self_collision=False)
    try:
        q, qd = s.state()
        k = 7
        for j, n in zip(s.character.joint_indices, s.character.joint_dofs):
            if n == 1:  # knees and elbows to mid-range: no joint-limit constraint acts
                lo, hi = pb.getJointInfo(s.character.body_id, j, physicsClientId=s.client)[8:10]
                q[k] = 0.5 * (lo + hi)
            k += 4 if n == 3 else 1
        s.reset(q, qd)
        rec = s.step(bent_target(s, 1.2))
        tau, lim = rec["tau"], s.torque_limit
        assert np.all(np.abs(tau) <= lim + 1e-9)
        assert np.all(tau[:6] == 0.0)  # free root
        assert np.any(np.isclose(np.abs(tau[6:]), lim[6:]))  # the clip is active somewhere
        # PyBullet received exactly the clipped torques: its velocity step is dt * ABA(tau)
        qdd = aba(s.model, Data(s.model), q, qd, tau)
        np.testing.assert_allclose(rec["qd"], qd + s.dt * qdd, atol=1e-9)
    finally:
        s.close()


def test_root_servo_holds_the_root_against_gravity():
    s = make("humanoid", sim_hz=600.0, control_hz=30.0, root_servo={"kp": 20000.0, "kd": 2000.0})
    free = make("humanoid", sim_hz=600.0, control_hz=30.0)
    try:
        q0, _ = s.state()
        qt = q0.copy()
        qt[1] += 0.3  # lift the root 30 cm
        for _ in range(15):
            rec, rec_free = s.step(qt), free.step(qt)
        assert rec["q"][1] == pytest.approx(qt[1], abs=0.03)
        assert rec_free["q"][1] < q0[1]  # without the servo the root target is ignored
    finally:
        s.close()
        free.close()


def test_same_inputs_give_identical_states():
    runs = []
    for _ in range(2):
        s = make("laikago", control_hz=60.0)
        qt = bent_target(s, 0.3)
        runs.append(np.stack([s.step(qt)["q"] for _ in range(6)]))
        s.close()
    assert np.array_equal(runs[0], runs[1])


def test_render_shows_the_character():
    from jt_bullet.render import render_frame
    from toolkit.render import Camera

    s = make("humanoid")
    try:
        frame = s.render(80, 60)  # camera 3 m away on the root (conf/character/humanoid.yaml)
        assert frame.shape == (60, 80, 3) and frame.dtype == np.uint8
        assert frame.astype(float).var() > 0.0
        q, qd = s.state()
        same_view = render_frame(s.client, q[:3], 80, 60, Camera(distance=3.0, pitch=-10.0))
        assert np.array_equal(frame, same_view)
        gone = q.copy()
        gone[0] += 50.0  # the character leaves the view; the ground stays
        s.reset(gone, qd)
        empty = render_frame(s.client, q[:3], 80, 60, Camera(distance=3.0, pitch=-10.0))
        changed = np.any(frame != empty, axis=2)
        assert 20 < changed.sum() < 0.5 * changed.size  # the body's pixels, not the whole frame
    finally:
        s.close()


def test_config_errors_are_one_line_jt_errors():
    with pytest.raises(JtError, match="whole number"):
        make(sim_hz=600.0, control_hz=70.0)
    with pytest.raises(JtError, match="valid keys"):
        make(no_such_key=1)
    with pytest.raises(JtError, match="root servo"):
        make(spd="bullet", root_servo={"kp": 1.0, "kd": 0.0})


def test_load_character_applies_gain_overrides():
    import pybullet as pb

    c = pb.connect(pb.DIRECT)
    try:
        ch = BulletSimulator.load_character(
            {"name": "humanoid", "kp": 75000.0, "joint_kd": {"neck": 7.0}}, c)
        assert np.all(ch.kp[:6] == 0.0) and np.all(ch.kp[6:] == 75000.0)
        neck = 6 + 3  # chest (3 DoFs), then the neck
        assert np.all(ch.kd[neck:neck + 3] == 7.0) and ch.kd[6] == pytest.approx(100.0)
        with pytest.raises(KeyError, match="no movable joint"):
            BulletSimulator.load_character({"name": "humanoid", "joint_kp": {"tail": 1.0}}, c)
    finally:
        pb.disconnect(c)
