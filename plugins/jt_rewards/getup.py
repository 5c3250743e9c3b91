"""The get-up task reward of ``003`` §5.1.2 (eqs 4-9), one term per factor, per control step.

``r_task = r_h · r_θ · r_v · r_p`` (eq 4) and ``r = r_task · r_natural`` (eq 2); ``r_natural``
(eq 3) is the action space's own penalty, read by the ``naturalness`` term (``jt_rewards.terms``).
The record is the get-up environment's step record (``jt_tasks.getup.env``): the measured style
features, the curve targets now and at ``s = 1``, the link angular velocities and the joint
rotations with the neutral standing pose's.

The phase variable of eqs 7-9, ``α = exp(−20 (1 − φ))`` with ``φ = p_h(s) / p_h(1)`` (eq 8), is
computed with ``φ`` clamped to ≤ 1 by default: a height curve that overshoots its end value would
give α > 1 and negative r_v, r_p (``clamp_phi: false`` is the literal formula).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from jt_rewards.base import RecordTerm


def phase_alpha(target_h: float, target_h_end: float, k: float = 20.0, clamp_phi: bool = True) -> float:
    """α = exp(−k (1 − φ)), φ = p_h(s) / p_h(1) (``003`` eq 8), φ ≤ 1 when ``clamp_phi``."""
    if not target_h_end > 0:
        raise ValueError(f"the final target height p_h(1) must be > 0, got {target_h_end}")
    phi = float(target_h) / float(target_h_end)
    if clamp_phi:
        phi = min(phi, 1.0)
    return math.exp(-float(k) * (1.0 - phi))


def rotation_angles(q: np.ndarray, q_hat: np.ndarray) -> np.ndarray:
    """Full rotation angles |log(q̂⁻¹ q)| ``(n,)`` in [0, π] of unit quaternions (x, y, z, w) ``(n, 4)``."""
    q = np.asarray(q, dtype=np.float64).reshape(-1, 4)
    q_hat = np.asarray(q_hat, dtype=np.float64).reshape(-1, 4)
    if q.shape != q_hat.shape:
        raise ValueError(f"joint rotations {q.shape} and neutral rotations {q_hat.shape} differ")
    from jt_rewards import kernels

    out = np.empty(len(q))
    kernels.rotation_angles(q, q_hat, out)  # every step: the formula below, compiled
    return out


def rotation_angles_numpy(q: np.ndarray, q_hat: np.ndarray) -> np.ndarray:
    """:func:`rotation_angles` in numpy (the reference the compiled kernel is held to)."""
    q = np.asarray(q, dtype=np.float64).reshape(-1, 4)
    q_hat = np.asarray(q_hat, dtype=np.float64).reshape(-1, 4)
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    q_hat = q_hat / np.linalg.norm(q_hat, axis=1, keepdims=True)
    dot = np.abs(np.sum(q * q_hat, axis=1))  # |w| of q̂⁻¹ q
    return 2.0 * np.arccos(np.clip(dot, 0.0, 1.0))


class GetupHeight(RecordTerm):
    """r_h = exp(−1.7 |h − p_h(s)|): track the neck-height curve (003 eq 5).

    Record keys:
        ``h`` (m): neck-base height above the mean terrain height; ``target_h`` (m): p_h(s).
    """

    @dataclasses.dataclass
    class Config:
        k: float = 1.7  # 1/m (003 eq 5)
        key: str = "h"  # measured neck height (jt)
        target_key: str = "target_h"  # p_h(s) (jt)

    def __call__(self, record: dict[str, Any]) -> float:
        p = self.params
        return math.exp(-p.k * abs(self.scalar(record, p.key) - self.scalar(record, p.target_key)))


class GetupTorso(RecordTerm):
    """r_θ = exp(−1.5 (|θx − p_θx(s)| + |θz − p_θz(s)|)): track the torso-angle curves (003 eq 6).

    Record keys:
        ``theta_x``, ``theta_z`` (rad): the side and front torso angles to up; ``target_theta_x``,
        ``target_theta_z`` (rad): the curves' values.
    """

    @dataclasses.dataclass
    class Config:
        k: float = 1.5  # 1/rad (003 eq 6)
        keys: list[str] = dataclasses.field(default_factory=lambda: ["theta_x", "theta_z"])  # measured (jt)
        target_keys: list[str] = dataclasses.field(
            default_factory=lambda: ["target_theta_x", "target_theta_z"])  # targets (jt)

    def __call__(self, record: dict[str, Any]) -> float:
        p = self.params
        err = sum(abs(self.scalar(record, a) - self.scalar(record, b)) for a, b in zip(p.keys, p.target_keys))
        return math.exp(-p.k * err)


class _Phased(RecordTerm):
    """Shared: α of eq 8 from the record."""

    def alpha(self, record: dict[str, Any]) -> float:
        p = self.params
        return phase_alpha(self.scalar(record, p.target_key), self.scalar(record, p.target_end_key),
                           p.k_alpha, p.clamp_phi)


class GetupVelocity(_Phased):
    """r_v = (1 − α) + α exp(−0.05 ‖ω‖): slow down as the character stands (003 eqs 7-8).

    Record keys:
        ``link_ang_vel``: the stacked link angular velocities ``(n_links, 3)`` (rad/s; ``‖ω‖`` is the
        norm of the stacked vector) or that norm; ``target_h``, ``target_h_end``: p_h(s), p_h(1).
    """

    @dataclasses.dataclass
    class Config:
        k: float = 0.05  # s/rad (003 eq 7)
        k_alpha: float = 20.0  # 003 eq 8
        clamp_phi: bool = True  # φ ≤ 1 so that α ≤ 1 (jt; 003 eq 8 is literal with false)
        key: str = "link_ang_vel"  # ω, (n_links, 3) or its norm (jt)
        target_key: str = "target_h"  # p_h(s) (jt)
        target_end_key: str = "target_h_end"  # p_h(1) (jt)

    def __call__(self, record: dict[str, Any]) -> float:
        w = np.asarray(self.get(record, self.params.key), dtype=np.float64)
        norm = float(w) if w.ndim == 0 else float(np.linalg.norm(w.reshape(-1)))
        if not math.isfinite(norm) or norm < 0:
            raise ValueError(f"reward term {self.term_name}: bad ‖ω‖ {norm}")
        a = self.alpha(record)
        return (1.0 - a) + a * math.exp(-self.params.k * norm)


class GetupPose(_Phased):
    """r_p = (1 − α) + α exp(−0.1 Σ_j |log(q̂_j⁻¹ q_j)|): a neutral standing pose at the end (003 eq 9).

    Record keys:
        ``joint_rotations`` ``(n_joints, 4)``: each joint's rotation relative to its parent (x, y, z,
        w; revolute joints as rotations about their axis); ``neutral_rotations`` ``(n_joints, 4)``:
        q̂; ``target_h``, ``target_h_end``. The log map's norm is the full rotation angle.
    """

    @dataclasses.dataclass
    class Config:
        k: float = 0.1  # 1/rad (003 eq 9)
        k_alpha: float = 20.0  # 003 eq 8
        clamp_phi: bool = True  # φ ≤ 1 (jt)
        key: str = "joint_rotations"  # q_j (jt)
        neutral_key: str = "neutral_rotations"  # q̂_j (jt)
        target_key: str = "target_h"  # p_h(s) (jt)
        target_end_key: str = "target_h_end"  # p_h(1) (jt)

    def __call__(self, record: dict[str, Any]) -> float:
        p = self.params
        dist = float(np.sum(rotation_angles(self.get(record, p.key), self.get(record, p.neutral_key))))
        a = self.alpha(record)
        return (1.0 - a) + a * math.exp(-p.k * dist)
