"""Clip loading, sampling, resampling, looping, mirroring and velocities on pybullet_data's clips."""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import os

import numpy as np
import pytest

from toolkit.motion import rotations as rot
from toolkit.motion.clips import Clip, ClipError, load_clip, load_humanoid_clips
from toolkit.motion.kinematics import forward_kinematics
from toolkit.motion.skeletons import HUMANOID, LAIKAGO, humanoid_clip_paths, motions_dir

EXPECTED = {"backflip", "cartwheel", "crawl", "dance_a", "dance_b", "getup_facedown", "getup_faceup",
            "jump", "kick", "punch", "roll", "run", "spin", "spinkick", "walk"}  # fmt: skip


@pytest.fixture(scope="module")
def clips() -> dict[str, Clip]:
    return {c.name: c for c in load_humanoid_clips()}


def _pose_interpolator():
    """PyBullet's own DeepMimic pose interpolator, loaded from its file (its package needs gym)."""
    import pybullet_utils

    path = os.path.join(os.path.dirname(pybullet_utils.__file__), "..", "pybullet_envs", "deep_mimic",
                        "env", "humanoid_pose_interpolator.py")  # fmt: skip
    if not os.path.exists(path):
        pytest.skip("pybullet_envs deep_mimic code not installed")
    spec = importlib.util.spec_from_file_location("jt_test_hpi", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.HumanoidPoseInterpolator()


def test_all_humanoid_clips_load(clips):
    assert set(clips) == EXPECTED
    assert len(humanoid_clip_paths()) == 15
    for c in clips.values():
        assert c.skeleton is HUMANOID and c.joints.shape == (c.n_frames, 36)
        assert np.all(np.diff(c.times) > 0) and c.times[0] == 0
        np.testing.assert_allclose(np.linalg.norm(c.root_rot, axis=1), 1.0, atol=1e-12)
        for j, s in zip(HUMANOID.joints, HUMANOID.q_slices.values()):
            if j.kind == "spherical":
                np.testing.assert_allclose(np.linalg.norm(c.joints[:, s], axis=1), 1.0, atol=1e-12)
                assert np.all(np.sum(c.joints[1:, s] * c.joints[:-1, s], axis=1) >= 0)  # sign-continuous
    assert clips["walk"].loop and not clips["getup_faceup"].loop
    assert clips["run"].fps == pytest.approx(30.0, rel=1e-4) and clips["jump"].fps == pytest.approx(60.0, rel=1e-3)


def test_wfirst_converted_once(clips):
    raw = json.load(open(clips["run"].source))["Frames"][3]
    chest_wxyz = np.array(raw[8:12])
    np.testing.assert_allclose(clips["run"].joint("chest")[3], chest_wxyz[[1, 2, 3, 0]] / np.linalg.norm(chest_wxyz))
    np.testing.assert_allclose(clips["run"].root_rot[3], np.array(raw[4:8])[[1, 2, 3, 0]] / np.linalg.norm(raw[4:8]))
    assert clips["run"].joint("right_knee")[3, 0] == raw[20]


def test_sampling_matches_pybullets_deepmimic_interpolator(clips):
    """Layout and interpolation agree with pybullet_envs' HumanoidPoseInterpolator.Slerp."""
    import pybullet as pb

    interp = _pose_interpolator()
    walk = clips["walk"]
    frames = json.load(open(walk.source))["Frames"]
    for i, frac in [(0, 0.0), (3, 0.25), (10, 0.5), (37, 0.9)]:
        interp.Slerp(frac, frames[i], frames[i + 1], pb)
        ref = np.array(interp.GetPose())  # root pos 3, root xyzw 4, joints in file order (xyzw)
        pos, q, joints = walk.sample(walk.times[i] + frac * (walk.times[i + 1] - walk.times[i]))
        np.testing.assert_allclose(pos, ref[:3], atol=1e-9)
        assert rot.quat_angle(q, ref[3:7]) < 1e-4  # the file is not exactly unit; pybullet slerps raw
        for j, s in zip(HUMANOID.joints, HUMANOID.q_slices.values()):
            r = ref[7 + s.start : 7 + s.stop]
            if j.kind == "spherical":
                assert rot.quat_angle(joints[s], r) < 1e-4, j.name
            else:
                assert joints[s][0] == pytest.approx(r[0], abs=1e-12), j.name


def test_sample_looping_and_clamping(clips):
    walk, getup = clips["walk"], clips["getup_faceup"]
    p, q, j = walk.sample(walk.times)
    np.testing.assert_allclose(p, walk.root_pos, atol=1e-12)
    assert np.all(rot.quat_angle(q, walk.root_rot) < 1e-7)
    # one cycle later: same pose, root shifted horizontally by the cycle offset
    off = walk.cycle_offset()
    assert off[1] == 0 and off[0] > 1.0
    t = np.array([0.1, 0.55, 1.0])
    p1, q1, j1 = walk.sample(t)
    p2, q2, j2 = walk.sample(t + 2 * walk.duration)
    np.testing.assert_allclose(p2, p1 + 2 * off, atol=1e-9)
    np.testing.assert_allclose(j2, j1, atol=1e-9)
    p3, _, _ = walk.sample(t - walk.duration)
    np.testing.assert_allclose(p3, p1 - off, atol=1e-9)
    # phase lookup (002 §4.2 FFC)
    np.testing.assert_allclose(walk.sample_phase(0.5)[2], walk.sample(0.5 * walk.duration)[2])
    # a non-looping clip clamps
    np.testing.assert_allclose(getup.sample(-1.0)[0], getup.root_pos[0])
    np.testing.assert_allclose(getup.sample(99.0)[0], getup.root_pos[-1])
    np.testing.assert_array_equal(getup.cycle_offset(), 0.0)


def test_resample(clips):
    walk, kick = clips["walk"], clips["kick"]
    same = walk.resample(30.0)  # the clip's own rate: the frames come back
    np.testing.assert_allclose(same.times, walk.times, atol=1e-9)
    np.testing.assert_allclose(same.joints, walk.joints, atol=1e-7)
    up = walk.resample(120.0)
    assert up.duration == pytest.approx(walk.duration) and up.fps == pytest.approx(120.0, rel=0.01)
    np.testing.assert_allclose(up.joints[::4], walk.joints, atol=1e-7)
    down = kick.resample(7.0)  # non-looping: exact rate, frames at k / 7
    np.testing.assert_allclose(np.diff(down.times), 1 / 7)
    assert down.times[-1] <= kick.duration
    with pytest.raises(ValueError):
        walk.resample(0.0)


def test_mirror(clips):
    run = clips["run"]
    m = run.mirror()
    assert m.mirrored and not m.mirror().mirrored
    np.testing.assert_allclose(m.mirror().joints, run.joints)
    np.testing.assert_allclose(m.root_pos[:, 2], -run.root_pos[:, 2])
    np.testing.assert_allclose(m.joint("left_knee"), run.joint("right_knee"))
    lq, rq = m.joint("left_hip"), run.joint("right_hip")
    np.testing.assert_allclose(lq, rq * [-1, -1, 1, 1])
    # FK of the mirror = reflected FK of the original with left/right links swapped
    k, km = run.fk(), m.fk()
    swap = HUMANOID.mirror_link_index()
    for a, b in ((km.joint_pos, k.joint_pos), (km.link_com, k.link_com)):
        np.testing.assert_allclose(a, b[:, swap] * [1, 1, -1], atol=1e-9)


def test_fk_plausible_and_matches_a_numpy_chain(clips):
    """Root-to-ankle length of a 0.25-scaled humanoid, and PyBullet's link frames agree with a
    plain transform chain built from the URDF joint offsets (checks joint order and xyzw feed)."""
    import pybullet as pb
    import pybullet_data

    run = clips["run"]
    rest = HUMANOID.rest_joints((1,))
    k0 = forward_kinematics(HUMANOID, [[0, 1, 0]], [[0, 0, 0, 1]], rest)
    ra, rt = HUMANOID.link_index("right_ankle"), HUMANOID.link_index("root")
    leg_rest = np.linalg.norm(k0.joint_pos[0, ra] - k0.joint_pos[0, rt])
    assert 0.8 < leg_rest < 1.0
    k = run.fk()
    leg0 = np.linalg.norm(k.joint_pos[0, ra] - run.root_pos[0])
    assert 0.6 < leg0 <= leg_rest + 1e-9
    kw = clips["walk"].fk()  # walking (unlike running) always has a foot on the ground, y-up
    assert np.all(kw.joint_pos[:, [ra, HUMANOID.link_index("left_ankle")], 1].min(axis=1) < 0.12)

    cid = pb.connect(pb.DIRECT)
    try:
        pb.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=cid)
        body = pb.loadURDF(HUMANOID.urdf, globalScaling=0.25, flags=pb.URDF_MAINTAIN_LINK_ORDER, physicsClientId=cid)
        n = pb.getNumJoints(body, physicsClientId=cid)
        info = [pb.getJointInfo(body, i, physicsClientId=cid) for i in range(n)]
        inertial = [pb.getDynamicsInfo(body, i, physicsClientId=cid)[3:5] for i in range(n)]
    finally:
        pb.disconnect(cid)
    assert tuple(i[12].decode() for i in info) == HUMANOID.links
    assert tuple(i[16] for i in info) == HUMANOID.link_parents
    local = {j.bullet_index: (j, s) for j, s in zip(HUMANOID.joints, HUMANOID.q_slices.values())}
    for f in (0, 11):
        # frames of each link's centre of mass; the base's is what resetBasePositionAndOrientation sets
        com_p, com_q = {-1: run.root_pos[f]}, {-1: run.root_rot[f]}
        for li, inf in enumerate(info):
            parent = inf[16]  # joint frame is given relative to the parent's inertial frame
            p = com_p[parent] + rot.quat_rotate(com_q[parent], np.array(inf[14]))
            q = rot.quat_multiply(com_q[parent], np.array(inf[15]))
            if li in local:
                j, s = local[li]
                jq = run.joints[f, s] if j.kind == "spherical" else rot.quat_from_axis_angle(j.axis, run.joints[f, s][0])
                q = rot.quat_multiply(q, jq)
            np.testing.assert_allclose(k.joint_pos[f, li], p, atol=1e-6)
            assert rot.quat_angle(k.link_rot[f, li], q) < 1e-6
            com_p[li] = p + rot.quat_rotate(q, np.array(inertial[li][0]))
            com_q[li] = rot.quat_multiply(q, np.array(inertial[li][1]))
            np.testing.assert_allclose(k.link_com[f, li], com_p[li], atol=1e-6)


def test_velocities_exact_for_constant_rates():
    n, dt = 30, 1 / 30
    t = np.arange(n) * dt
    w_root = np.array([0.3, -1.2, 0.5])  # world angular velocity
    w_hip = np.array([2.0, 0.1, -0.7])  # local angular velocity of the right hip
    v = np.array([1.0, 0.2, -0.4])
    q0 = rot.quat_from_expmap([0.2, 0.4, -0.1])
    root_rot = rot.quat_multiply(rot.quat_from_expmap(t[:, None] * w_root), q0)
    joints = HUMANOID.rest_joints((n,))
    s = HUMANOID.q_slices["right_hip"]
    joints[:, s] = rot.quat_multiply(q0, rot.quat_from_expmap(t[:, None] * w_hip))
    joints[:, HUMANOID.q_slices["left_knee"]] = -0.5 + 0.8 * t[:, None]
    clip = Clip("synthetic", HUMANOID, t, np.array([0, 0.9, 0]) + t[:, None] * v, root_rot, joints, loop=False)
    vel = clip.velocities()
    np.testing.assert_allclose(vel.root_lin, np.broadcast_to(v, (n, 3)), atol=1e-12)
    np.testing.assert_allclose(vel.root_ang, np.broadcast_to(w_root, (n, 3)), atol=1e-9)
    np.testing.assert_allclose(vel.joints[:, HUMANOID.dof_slices["right_hip"]], np.broadcast_to(w_hip, (n, 3)), atol=1e-9)
    np.testing.assert_allclose(vel.joints[:, HUMANOID.dof_slices["left_knee"]], 0.8, atol=1e-12)
    np.testing.assert_allclose(vel.joints[:, HUMANOID.dof_slices["chest"]], 0.0, atol=1e-12)
    # a looping clip's first and last frames are the same instant of the cycle: same velocities
    loop = dataclasses.replace(clip, loop=True)
    lv = loop.velocities()
    np.testing.assert_allclose(lv.root_lin[0], lv.root_lin[-1], atol=1e-9)
    np.testing.assert_allclose(lv.joints[0], lv.joints[-1], atol=1e-9)


def test_velocities_agree_with_pybullets_forward_differences(clips):
    """Central differences = mean of DeepMimic's two neighbouring forward differences (to 2nd order)."""
    import pybullet as pb

    interp = _pose_interpolator()
    walk = clips["walk"]
    frames = json.load(open(walk.source))["Frames"]
    vel = walk.velocities()
    for i in (5, 20):
        fwd = []
        for k in (i - 1, i):
            interp.Slerp(0.0, frames[k], frames[k + 1], pb)
            fwd.append((np.array(interp._baseLinVel), np.array(interp._rightHipVel), interp._rightKneeVel[0],
                        np.array(interp._baseAngVel)))  # fmt: skip
        np.testing.assert_allclose(vel.root_lin[i], 0.5 * (fwd[0][0] + fwd[1][0]), atol=1e-9)
        # world-frame root and local-frame joint angular velocities, as DeepMimic defines them
        np.testing.assert_allclose(vel.root_ang[i], 0.5 * (fwd[0][3] + fwd[1][3]), atol=0.02)
        np.testing.assert_allclose(vel.joints[i, HUMANOID.dof_slices["right_hip"]], 0.5 * (fwd[0][1] + fwd[1][1]), atol=0.02)
        assert vel.joints[i, HUMANOID.dof_slices["right_knee"]][0] == pytest.approx(0.5 * (fwd[0][2] + fwd[1][2]))


def test_laikago_clip():
    c = load_clip(os.path.join(motions_dir(), "laikago_walk.txt"))
    assert c.skeleton is LAIKAGO and c.loop and c.n_frames == 21 and c.joints.shape == (21, 12)
    assert c.fps == pytest.approx(16.0)
    k = c.fk()
    toes = [LAIKAGO.link_index(f"toe{leg}") for leg in ("FR", "FL", "RR", "RL")]
    z = k.joint_pos[:, toes, 2]
    assert np.all(z.min(axis=1) < 0.04) and np.all(z > -0.01)  # z-up; feet on the ground
    assert np.all(k.joint_pos[:, :, 2].max(axis=1) < c.root_pos[:, 2] + 0.1)  # legs below the body
    assert c.root_pos[-1, 1] - c.root_pos[0, 1] > 0.2  # walks along +y
    m = c.mirror()
    km = m.fk()
    ref = k.joint_pos[:, LAIKAGO.mirror_link_index()] * [-1, 1, 1]
    np.testing.assert_allclose(km.joint_pos, ref, atol=5e-3)  # the URDF is symmetric to 2.3 mm


# --------------------------------------------------------------------------- malformed files

GOOD = os.path.join(motions_dir(), "humanoid3d_walk.txt")


def _write(tmp_path, name: str, text: str) -> str:
    p = tmp_path / name
    p.write_text(text)
    return str(p)


def _good_json() -> dict:
    return json.load(open(GOOD))


CASES = {
    "bad_json": (lambda d: json.dumps(d)[:-40] + "}}", "bad JSON"),
    "truncated": (lambda d: json.dumps(d)[: len(json.dumps(d)) // 2], "bad JSON"),
    "missing_frames": (lambda d: json.dumps({"Loop": "wrap"}), "missing key 'Frames'"),
    "missing_loop": (lambda d: json.dumps({"Frames": d["Frames"]}), "missing key 'Loop'"),
    "bad_loop": (lambda d: json.dumps({**d, "Loop": "bounce"}), "'Loop'"),
    "short_frame": (lambda d: json.dumps({**d, "Frames": d["Frames"][:5] + [d["Frames"][5][:-1]] + d["Frames"][6:]}), "frame 5 has 43 values"),
    "nan": (lambda d: json.dumps({**d, "Frames": d["Frames"][:2] + [d["Frames"][2][:9] + [float("nan")] + d["Frames"][2][10:]]}), "non-finite value at frame 2"),
    "one_frame": (lambda d: json.dumps({**d, "Frames": d["Frames"][:1]}), "at least 2 frames"),
    "string_value": (lambda d: json.dumps({**d, "Frames": [d["Frames"][0], ["x"] * 44]}), "frame 1 holds a non-number"),
    "zero_duration": (lambda d: json.dumps({**d, "Frames": [[0.0] + d["Frames"][0][1:]] + d["Frames"][1:]}), "frame 0 has duration"),
    "zero_quat": (lambda d: json.dumps({**d, "Frames": [d["Frames"][0][:8] + [0, 0, 0, 0] + d["Frames"][0][12:]] + d["Frames"][1:]}), "zero quaternion for chest"),
    "not_object": (lambda d: json.dumps(d["Frames"]), "top level is list"),
}  # fmt: skip


@pytest.mark.parametrize("case", sorted(CASES))
def test_malformed_file_raises_one_clip_error(tmp_path, case):
    make, expect = CASES[case]
    path = _write(tmp_path, f"humanoid3d_{case}.txt", make(_good_json()))
    with pytest.raises(ClipError) as e:
        load_clip(path)
    msg = str(e.value)
    assert msg.startswith(path + ":") and expect in msg and "\n" not in msg


def test_missing_file_and_unknown_skeleton(tmp_path):
    with pytest.raises(ClipError, match="cannot read"):
        load_clip(tmp_path / "nope.txt")
    d = _good_json()
    path = _write(tmp_path, "mystery.txt", json.dumps({**d, "Frames": [f[:30] for f in d["Frames"]]}))
    with pytest.raises(ClipError, match="cannot tell the skeleton"):
        load_clip(path)
    # an unprefixed file of the right length is recognised by its frame size
    ok = _write(tmp_path, "mine.txt", json.dumps(d))
    assert load_clip(ok).skeleton is HUMANOID
