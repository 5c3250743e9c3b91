"""The task-reward terms of ``000`` §6.1.2 (eq 16) and the naturalness pass-through (eqs 2, 4).

``r_task = r_complete · r_ω · r_safety`` (eq 16) and ``r = r_task · r_naturalness`` (eq 2). All
four are episode-level terms: the jumping tasks give a sparse reward only at the end of a
successful episode (§6.1.2), so the record is the task's end-of-episode record.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from jt_rewards.base import RecordTerm


class TaskComplete(RecordTerm):
    """r_complete: 1 when the task was completed (bar cleared / landed), else 0 (000 eq 16).

    Record keys:
        ``success`` (bool or 0/1): the task's own completion test.
    """

    @dataclasses.dataclass
    class Config:
        key: str = "success"  # record key holding the completion flag (000 §6.1.2 "binary reward")

    def __call__(self, record: dict[str, Any]) -> float:
        return 1.0 if bool(self.get(record, self.params.key)) else 0.0


def mean_speed(value: Any) -> float:
    """``‖ω‖`` of eq 16: the average magnitude of the root angular velocity over the episode.

    Args:
        value: either that average already (a scalar, rad/s), or the per-step root angular
            velocities ``(n_steps, 3)`` (rad/s), whose norms are averaged here. A single
            ``(3,)`` vector counts as one step.

    Returns:
        The mean magnitude (rad/s), ``>= 0``.
    """
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 0:
        return float(a)
    if a.shape[-1] != 3:
        raise ValueError(f"root angular velocities must be (n_steps, 3), got shape {a.shape}")
    return float(np.mean(np.linalg.norm(a.reshape(-1, 3), axis=-1)))


class RootRotation(RecordTerm):
    """r_ω = exp(−k·‖ω‖), ‖ω‖ the episode's mean root angular speed, k = 0.02 (000 eq 16).

    Penalises excessive root rotation ("‖ω‖ is the average magnitude of the root angular
    velocities across the episode", ``000`` §6.1.2). Note: the magnitude is averaged, not the
    vector (a spinning root has a zero mean vector but a large mean magnitude).

    Record keys:
        ``root_ang_vel_mean`` (float, rad/s): ``(1/T) Σ_t ‖ω_t‖`` over the episode's control steps
        — or the per-step angular velocities ``(T, 3)``, averaged here.
    """

    @dataclasses.dataclass
    class Config:
        k: float = 0.02  # rate of the exponential, s/rad (000 §6.1.2, eq 16)
        key: str = "root_ang_vel_mean"  # record key: mean root angular speed (rad/s) or (T, 3)

    def __call__(self, record: dict[str, Any]) -> float:
        speed = mean_speed(self.get(record, self.params.key))
        if not math.isfinite(speed) or speed < 0:
            raise ValueError(f"reward term {self.term_name}: bad mean angular speed {speed}")
        return math.exp(-self.params.k * speed)


class Safety(RecordTerm):
    """r_safety: 0.7 for an unsafe head-first landing, 1.0 otherwise (000 §6.1.2, eq 16).

    Record keys:
        ``head_first_landing`` (bool or 0/1): the head touched the landing area first (the task
        decides; ``000``'s authors flag any head contact with the landing mat).
    """

    @dataclasses.dataclass
    class Config:
        factor: float = 0.7  # value for an unsafe (head-first) landing (000 §6.1.2)
        key: str = "head_first_landing"  # record key of the unsafe-landing flag

    def __call__(self, record: dict[str, Any]) -> float:
        return float(self.params.factor) if bool(self.get(record, self.params.key)) else 1.0


class Naturalness(RecordTerm):
    """r_naturalness: the action space's own penalty term, passed through (000 eqs 2, 4).

    For the P-VAE action space that is eq 4, ``1 − Clip((‖a_offset‖₁ / c_offset)², 0, 1)`` with
    the offset norm averaged over the episode for sparse-reward tasks; the action space computes
    it (``ActionSpace.penalty()``), the task averages/records it, this term only reads it.

    Record keys:
        ``naturalness`` (float in [0, 1]): the action space's penalty term for the episode.
    """

    @dataclasses.dataclass
    class Config:
        key: str = "naturalness"  # record key of the action space's penalty value (000 eq 4)

    def __call__(self, record: dict[str, Any]) -> float:
        value = self.scalar(record, self.params.key)
        if not -1e-9 <= value <= 1.0 + 1e-9:
            raise ValueError(f"reward term {self.term_name}: '{self.params.key}' = {value} is "
                             "outside [0, 1] (an action-space penalty is a factor in [0, 1])")
        return min(max(value, 0.0), 1.0)
