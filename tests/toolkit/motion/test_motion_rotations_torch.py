"""The torch 6D maps agree with the numpy ones and with scipy, and are differentiable."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from toolkit.motion import rotations as rot

torch = pytest.importorskip("torch")
rt = pytest.importorskip("toolkit.motion.rotations_torch")


def test_torch_6d_matches_numpy_and_scipy():
    rng = np.random.default_rng(0)
    raw = rng.normal(size=(64, 6))
    m_np = rot.sixd_to_matrix(raw)
    m_t = rt.sixd_to_matrix(torch.from_numpy(raw)).numpy()
    np.testing.assert_allclose(m_t, m_np, atol=1e-12)
    q_t = rt.sixd_to_quat(torch.from_numpy(raw)).numpy()
    assert np.all(q_t[:, 3] >= 0)
    np.testing.assert_allclose(Rotation.from_quat(q_t).as_matrix(), m_np, atol=1e-12)
    np.testing.assert_allclose(rt.matrix_to_sixd(torch.from_numpy(m_np)).numpy(), rot.matrix_to_6d(m_np))
    # half turns, the hard case for matrix → quaternion
    q_pi = rot.quat_from_axis_angle(np.eye(3), np.pi)
    out = rt.matrix_to_quat(torch.from_numpy(rot.quat_to_matrix(q_pi))).numpy()
    np.testing.assert_allclose(np.abs(out), np.abs(q_pi), atol=1e-12)


def test_torch_6d_is_differentiable():
    x = torch.randn(8, 6, dtype=torch.float64, requires_grad=True)
    target = torch.from_numpy(rot.quat_to_matrix(rot.quat_from_expmap(np.full((8, 3), 0.3))))
    loss = ((rt.sixd_to_matrix(x) - target) ** 2).sum()
    loss.backward()
    assert x.grad is not None and torch.isfinite(x.grad).all() and x.grad.abs().sum() > 0
