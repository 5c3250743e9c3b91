"""Spacetime bounds (002 §3.2 eq 2, §5.1): the 22-channel difference vector and its widths."""

from __future__ import annotations

import numpy as np
import pytest

from jt_tasks.spacetime import bounds as bd
from jt_tasks.spacetime.reference import SpacetimeReference, end_effector_links, heading_frame
from toolkit.errors import JtError
from toolkit.motion import rotations as rot
from toolkit.motion.skeletons import HUMANOID

NAMES = bd.channel_names(HUMANOID)
W = bd.widths(HUMANOID)


@pytest.fixture(scope="module")
def ref():
    return SpacetimeReference("run")


def state(ref, t):
    r = ref.sample(t)
    return bd.BodyState(r.q.copy(), r.com.copy(), r.ee.copy())


#: the channels of the authors' bound files, as their data/bounds readme lists them (0-21)
AUTHORS_CHANNELS = (
    "CoM x", "CoM y", "CoM z", "root", "chest", "neck", "right_hip", "right_knee", "right_ankle",
    "right_shoulder", "right_elbow", "right_wrist", "left_hip", "left_knee", "left_ankle", "left_shoulder",
    "left_elbow", "left_wrist", "right_ankle pos", "right_wrist pos", "left_ankle pos", "left_wrist pos")


def test_channels_are_in_the_order_of_the_authors_bound_files():
    """A width table copied from the authors' files lands on its channels (issue: the end
    effectors were right ankle, left ankle, right wrist, left wrist)."""
    ours = [n.replace("com_", "CoM ").replace("CoM x", "CoM x") for n in NAMES]
    ours = [f"{n[3:]} pos" if n.startswith("ee_") else n for n in ours]
    assert tuple(ours) == AUTHORS_CHANNELS
    from toolkit.motion.skeletons import HUMANOID as H

    links = ["base"] + list(H.links)
    assert [links[i + 1] for i in end_effector_links(H)] == ["right_ankle", "right_wrist", "left_ankle", "left_wrist"]


def test_22_channels_in_the_authors_order_with_the_paper_widths():
    assert len(NAMES) == 22
    assert NAMES[:4] == ("com_x", "com_y", "com_z", "root")
    assert NAMES[4:18] == HUMANOID.links[1:] and NAMES[18:] == bd.END_EFFECTOR_NAMES
    np.testing.assert_array_equal(W[:3], 0.2)  # 002 §5.1
    np.testing.assert_array_equal(W[3:18], 0.7)
    np.testing.assert_array_equal(W[18:], 0.5)


def test_equal_states_give_zero_on_every_channel(ref):
    for t in (0.0, 0.31, 1.7):
        a = state(ref, t)
        d = bd.difference(HUMANOID, a, state(ref, t))
        assert d.shape == (22,)
        np.testing.assert_allclose(d, 0.0, atol=1e-7)


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_a_com_offset_just_over_its_width_violates_and_just_under_does_not(ref, axis):
    a = state(ref, 0.2)
    for delta, out in ((0.201, True), (0.199, False)):
        com = a.com.copy()
        com[axis] += delta * (-1) ** axis
        d = bd.difference(HUMANOID, a, bd.BodyState(a.q, com, a.ee))
        v = bd.violations(d, W, NAMES)
        assert v == ([NAMES[axis]] if out else [])


def test_a_knee_turned_by_more_than_its_width_sets_that_channel(ref):
    a = state(ref, 0.4)
    q = a.q.copy()
    s = HUMANOID.q_slices["right_knee"]
    q[7:][s] += 0.75
    d = bd.difference(HUMANOID, a, bd.BodyState(q, a.com, a.ee))
    assert d[NAMES.index("right_knee")] == pytest.approx(0.75)
    assert bd.violations(d, W, NAMES) == ["right_knee"]
    # a spherical joint turned about any axis: its quaternion angle
    q = a.q.copy()
    s = HUMANOID.q_slices["left_shoulder"]
    turn = rot.quat_from_axis_angle(np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8]), 0.6)
    q[7:][s] = rot.quat_multiply(q[7:][s], turn)
    d = bd.difference(HUMANOID, a, bd.BodyState(q, a.com, a.ee))
    assert d[NAMES.index("left_shoulder")] == pytest.approx(0.6)
    assert bd.violations(d, W, NAMES) == []


def test_q_and_minus_q_give_the_same_angle(ref):
    a = state(ref, 0.55)
    q = a.q.copy()
    q[3:7] = -q[3:7]
    for j, s in zip(HUMANOID.joints, HUMANOID.q_slices.values()):
        if j.kind == "spherical":
            q[7:][s] = -q[7:][s]
    np.testing.assert_allclose(bd.difference(HUMANOID, a, bd.BodyState(q, a.com, a.ee)), 0.0, atol=1e-7)


def test_the_wrists_are_fixed_joints_whose_channels_stay_zero(ref):
    d = bd.difference(HUMANOID, state(ref, 0.0), state(ref, 0.4))
    assert d[NAMES.index("right_wrist")] == 0.0 and d[NAMES.index("left_wrist")] == 0.0
    assert d[NAMES.index("right_knee")] > 0.0


@pytest.mark.parametrize("axis", ["x", "z"])
def test_end_effector_channels_are_invariant_under_a_shared_yaw_and_translation(ref, axis):
    """Outside reference: PyBullet FK of both poses, then both turned and moved alike."""
    from toolkit.motion.kinematics import forward_kinematics

    qa, qb = ref.sample(0.1).q, ref.sample(0.5).q
    yaw = rot.quat_from_axis_angle(np.array([0.0, 1.0, 0.0]), 1.1)
    shift = np.array([3.0, 0.4, -2.0])

    def ee(q):
        kin = forward_kinematics(HUMANOID, q[None, :3], q[None, 3:7], q[None, 7:])
        return heading_frame(q, kin.joint_pos[0, list(end_effector_links(HUMANOID))], axis)

    def moved(q):
        out = q.copy()
        out[:3] = rot.quat_rotate(yaw, q[:3]) + shift
        out[3:7] = rot.quat_multiply(yaw, q[3:7])
        return out

    d0 = bd.difference(HUMANOID, bd.BodyState(qa, np.zeros(3), ee(qa)), bd.BodyState(qb, np.zeros(3), ee(qb)))
    d1 = bd.difference(HUMANOID, bd.BodyState(moved(qa), np.zeros(3), ee(moved(qa))),
                       bd.BodyState(moved(qb), np.zeros(3), ee(moved(qb))))
    assert d0[18:].max() > 0.05  # the two poses differ
    np.testing.assert_allclose(d1[18:], d0[18:], atol=1e-6)


def test_widths_per_channel_groups_and_switching_off():
    w = bd.widths(HUMANOID, [0.3, 0.2, 0.3], 0.7, 0.5, {"neck": 1.0, "ee_left_ankle": None, "end_effector": 0.4})
    assert list(w[:3]) == [0.3, 0.2, 0.3]
    assert w[NAMES.index("neck")] == 1.0 and w[NAMES.index("chest")] == 0.7
    assert w[NAMES.index("ee_right_ankle")] == 0.4
    assert bd.widths(HUMANOID, per_channel={"root": float("inf")})[3] == np.inf
    assert np.all(np.isinf(bd.widths(HUMANOID, orientation=None)[3:18]))
    d = np.full(22, 100.0)
    assert "root" not in bd.violations(d, bd.widths(HUMANOID, per_channel={"root": None}), NAMES)


@pytest.mark.parametrize("kw, match", [
    ({"com": 0.0}, "must be > 0"),
    ({"orientation": -0.7}, "must be > 0"),
    ({"per_channel": {"knee": 0.5}}, "unknown bound channel"),
    ({"per_channel": {"neck": "wide"}}, "must be a number"),
    ({"com": [0.2, 0.2]}, "one width or three"),
])
def test_bad_widths_are_one_line_errors(kw, match):
    with pytest.raises(JtError, match=match) as e:
        bd.widths(HUMANOID, **kw)
    assert "\n" not in str(e.value)


def test_phase_tables_interpolate_linearly_between_evenly_spaced_rows():
    """K rows over phase [0, 1] (row k at k / (K - 1)), linear in between, taken at phase mod 1
    (authors' code); an off (inf) row keeps its channel off up to its neighbours."""
    base = bd.widths(HUMANOID)
    t = bd.width_table(HUMANOID, base, [{"com": 0.1}, {"com": 0.3, "right_knee": None}, {"com_y": 0.5}])
    assert t.shape == (3, 22)
    cy, knee, neck = NAMES.index("com_y"), NAMES.index("right_knee"), NAMES.index("neck")
    assert bd.widths_at(t, 0.0)[cy] == 0.1 and bd.widths_at(t, 0.5)[cy] == 0.3 and bd.widths_at(t, 0.999)[cy] > 0.49
    assert bd.widths_at(t, 0.25)[cy] == pytest.approx(0.2) and bd.widths_at(t, 0.75)[cy] == pytest.approx(0.4)
    assert bd.widths_at(t, 1.25)[cy] == pytest.approx(0.2)  # mod 1
    assert bd.widths_at(t, 0.0)[knee] == 0.7 and np.isinf(bd.widths_at(t, 0.3)[knee]) and np.isinf(bd.widths_at(t, 0.7)[knee])
    assert all(bd.widths_at(t, p)[neck] == 0.7 for p in np.linspace(0, 1, 11))  # rows override only what they name
    one = bd.width_table(HUMANOID, base, [[0.25] * 22])
    assert np.array_equal(bd.widths_at(one, 0.6), np.full(22, 0.25))
    assert bd.width_table(HUMANOID, base, []).shape == (0, 22)


@pytest.mark.parametrize("rows, match", [
    ([{"knee": 0.5}], r"width_table\[0\]\.knee: unknown bound channel"),
    ([{"com": 0.1}, {"com": 0.0}], r"width_table\[1\]\.com=0.0: a bound width must be > 0"),
    ([[0.2, 0.2]], "a list of 22 widths"),
    (["wide"], "a row is"),
])
def test_bad_phase_tables_are_one_line_errors(rows, match):
    with pytest.raises(JtError, match=match) as e:
        bd.width_table(HUMANOID, bd.widths(HUMANOID), rows)
    assert "\n" not in str(e.value)
