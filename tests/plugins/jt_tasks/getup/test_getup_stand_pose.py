"""The standing pose (task.stand_pose, issue 29 item 4): the clip's final frame against its symmetric
stance, on real PyBullet. Its bad value is in test_getup_stage1.py."""

from __future__ import annotations

import numpy as np
import pytest

from tests.plugins.jt_tasks.getup.test_getup_stage1 import make_task


@pytest.fixture(scope="module")
def envs():
    """A standing-start env with each pose (the clip's frame, the symmetric stance)."""
    made = {k: make_task(f"task.stand_pose={k}", "task.p_standing=1.0", "task.p_fallen=0").make_env(None, seed=0)
            for k in ("clip", "symmetric")}
    yield made
    for e in made.values():
        e.close()


def _ankle_feedback_stands(env, q: np.ndarray, seconds: float, kx: float = -20.0, kv: float = -4.0) -> float:
    """Seconds (of ``seconds``) the pose ``q`` stays up (root above 0.6 m) when every joint is held
    at ``q`` by PD except the ankles, which pitch by ``kx`` (rad/m) times the CoM's forward offset
    from the feet's centre plus ``kv`` (rad s/m) times its forward speed: one sagittal balance law."""
    from toolkit.motion import rotations as rot
    from toolkit.motion.skeletons import HUMANOID

    sim = env.sim
    sim.reset(np.array(q), np.zeros(sim.model.n_v))
    feet = [sim.link_index(n) for n in ("right_ankle", "left_ankle")]
    m = sim.masses
    for k in range(int(seconds * sim.control_hz)):
        now, _ = sim.state()
        if now[1] < 0.6:
            return k / sim.control_hz
        boxes = [sim.aabb(f) for f in feet]
        foot_x = float(np.mean([0.5 * (lo[0] + hi[0]) for lo, hi in boxes]))
        v, _ = sim.link_velocities()
        pitch = kx * (sim.com()[0] - foot_x) + kv * float(m @ v[:, 0] / m.sum())
        target = np.array(q)
        target[:7] = now[:7]
        for name in ("right_ankle", "left_ankle"):
            s = HUMANOID.q_slices[name]
            sl = slice(7 + s.start, 7 + s.stop)
            target[sl] = rot.quat_multiply(q[sl], rot.quat_from_axis_angle(np.array([0.0, 0.0, 1.0]), pitch))
        sim.step(target)
    return seconds


def test_the_symmetric_stance_mirrors_the_left_leg_and_rests_flat_footed(envs):
    from jt_tasks.getup.env import joint_rotations
    from jt_tasks.getup.ground import CLEARANCE, lowest_point
    from toolkit.motion import rotations as rot
    from toolkit.motion.skeletons import HUMANOID

    clip, sym = envs["clip"].stand_state[0], envs["symmetric"].stand_state[0]
    mirrored = HUMANOID.mirror_joints(sym[7:])
    for part in ("hip", "knee"):  # the right leg is the left one's mirror image, the left the clip's
        r, l_ = HUMANOID.q_slices[f"right_{part}"], HUMANOID.q_slices[f"left_{part}"]
        assert np.allclose(mirrored[r], sym[7:][r], atol=1e-9)
        assert np.allclose(sym[7:][l_], clip[7:][l_])
    assert not np.allclose(clip[7:][HUMANOID.q_slices["right_hip"]], sym[7:][HUMANOID.q_slices["right_hip"]], atol=0.01)
    for q in (clip, sym):
        assert lowest_point(q) == pytest.approx(CLEARANCE, abs=1e-6)
    sim = envs["symmetric"].sim
    sim.reset(np.array(sym), np.zeros(sim.model.n_v))
    for name in ("right_ankle", "left_ankle"):  # both soles flat (each ankle turned for it): the foot's up axis vertical
        _, o = sim.link_pose(sim.link_index(name))
        assert rot.quat_rotate(o, np.array([0.0, 1.0, 0.0]))[1] > np.cos(np.radians(1.0))
    assert np.allclose(envs["symmetric"].neutral, joint_rotations(sym))  # eq 9's q̂ is the stance


def test_a_standing_start_is_the_chosen_pose(envs):
    for kind, e in envs.items():
        e.reset(seed=0)
        assert e.start_kind == "standing"
        assert np.allclose(e.sim.state()[0], e.stand_state[0], atol=1e-6), kind


def test_one_sagittal_ankle_law_keeps_the_symmetric_stance_up_and_not_the_clips_frame(envs):
    """Why the clip's frame is hard to stand in (docs/journal/getup.md, "Why a held standing pose falls"):
    held by PD both fall within 2 s; with the ankles pitched on the CoM's forward offset and speed,
    the symmetric stance stands 5 s and the clip's frame (its legs unlike, one sole tilted) still falls
    within 2 s, sideways."""
    clip, sym = envs["clip"], envs["symmetric"]
    assert _ankle_feedback_stands(clip, clip.stand_state[0], 3.0, 0.0, 0.0) < 2.0
    assert _ankle_feedback_stands(sym, sym.stand_state[0], 3.0, 0.0, 0.0) < 2.0
    assert _ankle_feedback_stands(sym, sym.stand_state[0], 5.0) == 5.0
    assert _ankle_feedback_stands(clip, clip.stand_state[0], 5.0) < 2.0


def test_constraint_servos_hold_the_symmetric_stance_where_stable_pd_lets_it_fall(envs):
    """Why SPD cannot hold a stance (docs/journal/getup.md, "Stable PD's planted ankle, and servos solved with the contacts"): Stable PD
    predicts a planted foot's acceleration from its own tiny inertia, so the ankle's torque is a
    small share of its gain's. ``spd=servo`` (PyBullet's constraint motors, solved with the contacts)
    holds the symmetric stance 5 s with no feedback at all, also from perturbed starts; the clip's
    frame (one foot 2 cm up) is no stance and falls either way."""
    from tests.plugins.jt_tasks.getup.test_getup_stage1 import make_task

    sym = envs["symmetric"]
    assert _ankle_feedback_stands(sym, sym.stand_state[0], 3.0, 0.0, 0.0) < 2.0  # SPD (df)
    made = {k: make_task("spd=servo", f"task.stand_pose={k}", "task.p_standing=1.0", "task.p_fallen=0")
            .make_env(None, seed=0) for k in ("clip", "symmetric")}
    try:
        servo = made["symmetric"]
        assert servo.sim.spd_name == "servo"
        rng = np.random.default_rng(0)
        for k in range(3):
            q = np.array(servo.stand_state[0])
            if k:
                q[7:] += rng.normal(0.0, 0.02, size=len(q) - 7)  # ~0.02 rad per joint (PyBullet normalises)
            assert _ankle_feedback_stands(servo, q, 5.0, 0.0, 0.0) == 5.0, k
        clip = made["clip"]
        assert _ankle_feedback_stands(clip, clip.stand_state[0], 3.0, 0.0, 0.0) < 2.0
    finally:
        for e in made.values():
            e.close()
