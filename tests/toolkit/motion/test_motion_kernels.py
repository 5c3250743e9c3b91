"""The compiled one-pose conversions equal the vectorised numpy paths bit for bit (PD targets are
built with them: a last-digit change would change every trajectory)."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.mark.parametrize("skeleton_name", ["humanoid", "laikago"])
def test_dofs_to_joints_of_one_pose_has_the_bits_of_the_batched_path(skeleton_name):
    from toolkit.motion.skeletons import SKELETONS

    sk = SKELETONS[skeleton_name]
    rng = np.random.default_rng(0)
    # wide angles (|v| > pi), tiny ones (the series branch), exact zeros
    dofs = np.concatenate([rng.normal(0, 2.0, (300, sk.n_dof)), rng.normal(0, 1e-7, (50, sk.n_dof)),
                           np.zeros((1, sk.n_dof))])
    batched = sk.dofs_to_joints(dofs)  # (n, n_q): the numpy path
    one = np.array([sk.dofs_to_joints(d) for d in dofs])
    assert batched.shape == one.shape == (len(dofs), sk.n_q)
    assert np.array_equal(batched.view(np.uint64), one.view(np.uint64))  # signed zeros too


def test_limit_targets_of_one_pose_has_the_bits_of_the_batched_path():
    from toolkit.motion.skeletons import SKELETONS
    from toolkit.priors.limits import canonical_expmaps, joint_limits, limit_targets

    sk = SKELETONS["humanoid"]
    low, high = joint_limits(sk)
    rng = np.random.default_rng(1)
    dofs = np.concatenate([rng.normal(0, 1.0, (300, sk.n_dof)), rng.normal(0, 3.0, (100, sk.n_dof))])
    for d in dofs:  # the compiled path where nothing wraps, numpy's where one does: the same bits
        want = np.clip(canonical_expmaps(sk, d[None, :]), low, high)[0]
        assert np.array_equal(limit_targets(sk, d).view(np.uint64), want.view(np.uint64))


@pytest.mark.parametrize("clamped", [True, False])
@pytest.mark.parametrize("dim", [0, 3])
def test_compiled_bspline_has_the_bits_of_the_basis_matrix_path(clamped, dim):
    from toolkit.motion.splines import BSplineCurve, basis_matrix

    rng = np.random.default_rng(2)
    control = rng.normal(size=(9,) if dim == 0 else (9, dim))
    c = BSplineCurve(control, clamped)
    s = np.concatenate([rng.uniform(-0.2, 1.2, 200), [0.0, 1.0, 0.5]])
    want = np.tensordot(basis_matrix(s, c.knots), control, axes=([-1], [0]))
    assert np.array_equal(c(s), want)
    assert c(0.3).shape == want[0].shape
    assert np.array_equal(c(0.3), np.tensordot(basis_matrix(0.3, c.knots), control, axes=([-1], [0])))
    b = np.empty((len(s), 9))
    from toolkit.motion import kernels

    kernels.bspline_basis(s, c.knots, 3, b)
    assert np.array_equal(b.view(np.uint64), basis_matrix(s, c.knots).view(np.uint64))


def test_quat_mul_is_quat_multiply_bit_for_bit_and_conjugates_by_sign():
    from toolkit.motion import rotations as rot
    from toolkit.motion.kernels import quat_mul

    rng = np.random.default_rng(5)
    for _ in range(50):
        a, b = rot.quat_normalize(rng.standard_normal(4)), rot.quat_normalize(rng.standard_normal(4))
        assert np.array_equal(np.array(quat_mul(*a, *b)), rot.quat_multiply(a, b))
        c = rot.quat_conjugate(a)
        assert np.array_equal(np.array(quat_mul(-a[0], -a[1], -a[2], a[3], *b)), rot.quat_multiply(c, b))
