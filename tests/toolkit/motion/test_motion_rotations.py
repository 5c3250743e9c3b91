"""Rotation utilities against scipy.spatial.transform.Rotation (the outside reference) and edge cases."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from toolkit.motion import rotations as rot

RNG = np.random.default_rng(0)


def random_quats(n: int, seed: int = 0) -> np.ndarray:
    q = np.random.default_rng(seed).normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def same_rotation(a: np.ndarray, b: np.ndarray, atol: float = 1e-9) -> bool:
    return bool(np.all(rot.quat_angle(a, b) < atol))


def test_multiply_rotate_matrix_match_scipy():
    a, b = random_quats(200, 1), random_quats(200, 2)
    v = RNG.normal(size=(200, 3))
    ra, rb = Rotation.from_quat(a), Rotation.from_quat(b)
    assert same_rotation(rot.quat_multiply(a, b), (ra * rb).as_quat())
    np.testing.assert_allclose(rot.quat_rotate(a, v), ra.apply(v), atol=1e-12)
    np.testing.assert_allclose(rot.quat_to_matrix(a), ra.as_matrix(), atol=1e-12)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", rot.quat_to_matrix(a), v), ra.apply(v), atol=1e-12)
    assert same_rotation(rot.quat_conjugate(a), ra.inv().as_quat())


def test_vectorised_over_leading_dims():
    q = random_quats(24, 3).reshape(2, 3, 4, 4)
    v = RNG.normal(size=(2, 3, 4, 3))
    assert rot.quat_rotate(q, v).shape == (2, 3, 4, 3)
    assert rot.quat_to_matrix(q).shape == (2, 3, 4, 3, 3)
    assert rot.quat_to_6d(q).shape == (2, 3, 4, 6)
    assert rot.quat_to_expmap(q).shape == (2, 3, 4, 3)
    assert rot.quat_slerp(q, q[::-1], np.full((2, 3, 4), 0.3)).shape == (2, 3, 4, 4)
    # broadcasting one rotation against many vectors
    np.testing.assert_allclose(rot.quat_rotate(q[0, 0, 0], v)[1, 2, 3], Rotation.from_quat(q[0, 0, 0]).apply(v[1, 2, 3]))


def test_matrix_to_quat_matches_scipy_including_half_turns():
    q = random_quats(300, 4)
    # half turns about random axes and about coordinate axes: the hard cases for Shepperd
    axes = np.vstack([np.eye(3), RNG.normal(size=(20, 3))])
    q_pi = rot.quat_from_axis_angle(axes, np.pi)
    for qq in (q, q_pi):
        m = Rotation.from_quat(qq).as_matrix()
        out = rot.matrix_to_quat(m)
        assert np.all(out[:, 3] >= 0)
        np.testing.assert_allclose(np.linalg.norm(out, axis=1), 1.0, atol=1e-12)
        np.testing.assert_allclose(rot.quat_to_matrix(out), m, atol=1e-12)
        assert same_rotation(out, Rotation.from_matrix(m).as_quat(), atol=1e-7)


def test_expmap_and_log_match_scipy():
    q = random_quats(300, 5)
    v = Rotation.from_quat(q).as_rotvec()
    np.testing.assert_allclose(rot.quat_to_expmap(q), v, atol=1e-12)
    assert same_rotation(rot.quat_from_expmap(v), q)
    big = RNG.normal(size=(100, 3)) * 3.0  # |v| up to ~10 rad, beyond pi
    np.testing.assert_allclose(rot.expmap_to_matrix(big), Rotation.from_rotvec(big).as_matrix(), atol=1e-12)


@pytest.mark.parametrize("angle", [0.0, 1e-12, 1e-9, 1e-7, 1e-5, 0.5, np.pi - 1e-3, np.pi - 1e-7, np.pi])
def test_exp_log_round_trip_edge_angles(angle: float):
    axes = np.vstack([np.eye(3), RNG.normal(size=(10, 3))])
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    v = axes * angle
    q = rot.quat_from_expmap(v)
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-15)
    back = rot.quat_to_expmap(q)
    if angle < np.pi:  # the log map is one-to-one below pi
        np.testing.assert_allclose(back, v, atol=1e-13, rtol=1e-12)
    else:  # at pi, v and -v are the same rotation
        np.testing.assert_allclose(np.abs(back), np.abs(v), atol=1e-12)
    np.testing.assert_allclose(rot.expmap_to_matrix(back), Rotation.from_rotvec(v).as_matrix(), atol=1e-12)
    # double cover: q and -q have the same log, matrix, 6D, and zero angle between them
    np.testing.assert_allclose(rot.quat_to_expmap(-q), back, atol=1e-13)
    np.testing.assert_allclose(rot.quat_to_6d(-q), rot.quat_to_6d(q), atol=1e-15)
    np.testing.assert_allclose(rot.quat_angle(q, -q), 0.0, atol=1e-7)
    ax, ang = rot.quat_to_axis_angle(q)
    np.testing.assert_allclose(ang, angle, atol=1e-13)
    if angle > 1e-9:
        np.testing.assert_allclose(np.abs(np.sum(ax * axes, axis=1)), 1.0, atol=1e-9)


def test_log_of_tiny_angle_keeps_precision():
    # acos-based log maps lose everything below ~1e-8; the series must not
    v = np.array([[3e-10, -1e-10, 2e-10]])
    np.testing.assert_allclose(rot.quat_to_expmap(rot.quat_from_expmap(v)), v, rtol=1e-9)
    np.testing.assert_allclose(rot.quat_to_expmap(rot.quat_from_expmap(-v)), -v, rtol=1e-9)


def test_beyond_pi_gives_the_equivalent_short_rotation():
    axis = np.array([0.0, 0.6, 0.8])
    v = axis * (np.pi + 0.2)
    back = rot.quat_to_expmap(rot.quat_from_expmap(v))
    np.testing.assert_allclose(back, -axis * (np.pi - 0.2), atol=1e-12)


def test_axis_angle_matches_scipy():
    axes = RNG.normal(size=(50, 3))
    angles = RNG.uniform(-np.pi, np.pi, size=50)
    q = rot.quat_from_axis_angle(axes, angles)
    unit = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    assert same_rotation(q, Rotation.from_rotvec(unit * angles[:, None]).as_quat())
    ax, ang = rot.quat_to_axis_angle(q)
    np.testing.assert_allclose(ax * ang[:, None], Rotation.from_rotvec(unit * angles[:, None]).as_rotvec(), atol=1e-12)
    ax0, ang0 = rot.quat_to_axis_angle(rot.quat_identity((2,)))
    np.testing.assert_array_equal(ax0, [[1, 0, 0], [1, 0, 0]])
    np.testing.assert_array_equal(ang0, [0, 0])


def test_slerp_matches_scipy_and_takes_shortest_path():
    a, b = random_quats(50, 6), random_quats(50, 7)
    ts = np.linspace(0, 1, 7)
    for i in range(50):
        ref = Slerp([0, 1], Rotation.from_quat([a[i], b[i]]))(ts).as_quat()
        out = rot.quat_slerp(np.broadcast_to(a[i], (7, 4)), np.broadcast_to(b[i], (7, 4)), ts)
        assert same_rotation(out, ref, atol=1e-9)
        # -b is the same end rotation: same path
        assert same_rotation(rot.quat_slerp(np.broadcast_to(a[i], (7, 4)), np.broadcast_to(-b[i], (7, 4)), ts), ref)
    # endpoints exactly, constant angular speed
    out = rot.quat_slerp(a, b, np.zeros(50))
    assert same_rotation(out, a, atol=1e-12)
    total = rot.quat_angle(a, b)
    np.testing.assert_allclose(rot.quat_angle(a, rot.quat_slerp(a, b, np.full(50, 0.25))), 0.25 * total, atol=1e-9)
    # nearly identical endpoints stay finite and accurate
    tiny = rot.quat_multiply(a, rot.quat_from_expmap(np.tile([1e-10, 0, 0], (50, 1))))
    mid = rot.quat_slerp(a, tiny, np.full(50, 0.5))
    assert np.all(np.isfinite(mid)) and same_rotation(mid, a, atol=1e-9)


def test_6d_round_trips_and_gram_schmidt():
    q = random_quats(200, 8)
    m = rot.quat_to_matrix(q)
    d6 = rot.matrix_to_6d(m)
    np.testing.assert_array_equal(d6[:, :3], m[:, :, 0])  # columns, not rows
    np.testing.assert_array_equal(d6[:, 3:], m[:, :, 1])
    np.testing.assert_allclose(rot.sixd_to_matrix(d6), m, atol=1e-12)
    assert same_rotation(rot.sixd_to_quat(d6), q)
    # Gram-Schmidt: scaling the columns or adding col0 to col1 changes nothing
    skew = np.concatenate([3.0 * d6[:, :3], 0.5 * d6[:, 3:] + 2.0 * d6[:, :3]], axis=1)
    np.testing.assert_allclose(rot.sixd_to_matrix(skew), m, atol=1e-12)
    # arbitrary inputs, degenerate ones included, give proper rotations
    raw = np.vstack([RNG.normal(size=(100, 6)), np.zeros((1, 6)), [[1, 0, 0, 2, 0, 0]], [[0, 0, 0, 0, 1, 0]]])
    r = rot.sixd_to_matrix(raw)
    assert np.all(np.isfinite(r))
    np.testing.assert_allclose(np.einsum("nji,njk->nik", r, r), np.broadcast_to(np.eye(3), r.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(r), 1.0, atol=1e-12)


def test_normalize_canonical_align():
    q = random_quats(10, 9) * 3.0
    n = rot.quat_normalize(q)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0)
    np.testing.assert_array_equal(rot.quat_normalize(np.zeros((1, 4))), [[0, 0, 0, 1]])
    assert np.all(rot.quat_canonical(-n)[:, 3] >= 0)
    seq = rot.quat_slerp(np.tile(n[0], (20, 1)), np.tile(n[1], (20, 1)), np.linspace(0, 1, 20))
    flipped = seq * np.where(np.arange(20) % 3 == 0, -1.0, 1.0)[:, None]
    aligned = rot.align_hemisphere(flipped)
    assert np.all(np.sum(aligned[1:] * aligned[:-1], axis=1) > 0)
    assert same_rotation(aligned, seq)


def test_one_quaternion_to_matrix_is_the_vectorised_result_bit_for_bit():
    """``quat_to_matrix`` of one ``(4,)`` quaternion takes a Python-float path (the per-step
    observation's); it must be the batched path's result exactly, tiny and zero quaternions too."""
    rng = np.random.default_rng(0)
    for scale in (1e-13, 1e-6, 1.0, 1e4):
        qs = rng.standard_normal((2000, 4)) * scale
        batched = rot.quat_to_matrix(qs)
        for q, m in zip(qs, batched):
            assert np.array_equal(rot.quat_to_matrix(q), m)
    assert np.array_equal(rot.quat_to_matrix(np.zeros(4)), np.eye(3))
    assert rot.quat_to_matrix([0.0, 0.0, 0.0, 1.0]).shape == (3, 3)


def test_rotating_by_one_quaternion_is_the_vectorised_result_bit_for_bit():
    """``quat_rotate`` with one ``(4,)`` quaternion (the envs' heading frames) takes a shorter path;
    its result, signed zeros included, is the batched path's for one vector and for many."""
    rng = np.random.default_rng(1)
    for scale in (1e-6, 1.0, 1e3):
        for shape in [(3,), (7, 3), (2, 5, 3)]:
            for _ in range(200):
                q = rot.quat_normalize(rng.standard_normal(4))
                v = rng.standard_normal(shape) * scale
                fast = rot.quat_rotate(q, v)
                batched = rot.quat_rotate(q[None], v[None] if v.ndim == 1 else v)
                batched = batched[0] if v.ndim == 1 else batched
                assert fast.shape == v.shape
                assert np.array_equal(fast, batched) and np.array_equal(np.signbit(fast), np.signbit(batched))


def test_one_quaternion_normalize_canonical_multiply_are_the_vectorised_results():
    """The ``(4,)`` paths of ``quat_normalize``, ``quat_canonical`` and ``quat_multiply`` (every
    episode's end goes through them) give the batched results bit for bit, signed zeros, zero and
    NaN quaternions included."""
    rng = np.random.default_rng(9)

    def same(x, y):
        return x.shape == y.shape and np.array_equal(x, y, equal_nan=True) and np.array_equal(np.signbit(x), np.signbit(y))

    cases = [rng.standard_normal(4) * s for s in (1e-13, 1e-6, 1.0, 1e3) for _ in range(500)]
    cases += [np.zeros(4), np.array([0.0, 0.0, 0.0, -0.0]), np.array([np.nan, 0.0, 0.0, 1.0]), np.array([0.0, -1.0, 0.0, -0.5])]
    for a, b in zip(cases, cases[1:] + cases[:1]):
        assert same(rot.quat_normalize(a), rot.quat_normalize(a[None])[0])
        assert same(rot.quat_canonical(a), rot.quat_canonical(a[None])[0])
        assert same(rot.quat_multiply(a, b), rot.quat_multiply(a[None], b)[0])
