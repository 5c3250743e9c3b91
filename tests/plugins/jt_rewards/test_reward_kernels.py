"""Compiled reward pieces against their numpy formulas (``jt_rewards.kernels``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from jt_rewards.getup import rotation_angles, rotation_angles_numpy


def test_rotation_angles_kernel_is_the_numpy_formula():
    rng = np.random.default_rng(0)
    q, q_hat = rng.normal(size=(200, 4)), rng.normal(size=(200, 4))  # not normalised: both normalise
    q_hat[0] = q[0] * 3.0  # the same rotation: angle 0 (the clip at 1)
    q_hat[1] = -q[1]  # the other cover: angle 0
    np.testing.assert_allclose(rotation_angles(q, q_hat), rotation_angles_numpy(q, q_hat), rtol=0, atol=1e-12)
    angles = rotation_angles(q, q_hat)
    assert angles[0] < 1e-6 and angles[1] < 1e-6 and np.all((angles >= 0) & (angles <= math.pi))
    half = np.array([[0.0, 0.0, math.sin(0.6), math.cos(0.6)]])  # 1.2 rad about z
    assert rotation_angles(half, np.array([[0.0, 0.0, 0.0, 1.0]]))[0] == pytest.approx(1.2, abs=1e-12)

