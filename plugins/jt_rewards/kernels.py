"""Compiled pieces of reward terms that run every control step (numba).

Each kernel is its numpy counterpart's formula on scalars (``getup.rotation_angles``), held
against it in ``tests/plugins/jt_rewards/test_reward_kernels.py``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def rotation_angles(q: np.ndarray, q_hat: np.ndarray, out: np.ndarray) -> None:
    """Full rotation angles ``out`` ``(n,)`` of ``q̂⁻¹ q``: ``2 acos(clip(|q̂ · q|, 0, 1))`` of the
    normalised quaternions ``q``, ``q_hat`` ``(n, 4)``."""
    for i in range(q.shape[0]):
        a = math.sqrt(q[i, 0] * q[i, 0] + q[i, 1] * q[i, 1] + q[i, 2] * q[i, 2] + q[i, 3] * q[i, 3])
        b = math.sqrt(q_hat[i, 0] * q_hat[i, 0] + q_hat[i, 1] * q_hat[i, 1] + q_hat[i, 2] * q_hat[i, 2]
                      + q_hat[i, 3] * q_hat[i, 3])
        d = 0.0
        for k in range(4):
            d += (q[i, k] / a) * (q_hat[i, k] / b)
        out[i] = 2.0 * math.acos(min(max(abs(d), 0.0), 1.0))
