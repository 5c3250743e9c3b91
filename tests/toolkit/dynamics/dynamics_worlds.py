"""Helpers for the dynamics tests: every thesis character, each in its own PyBullet client.

Each (character, base) pair gets its own DIRECT client so that no body is ever removed: PyBullet
caches its inverse-dynamics trees per multibody pointer and a reused slot makes
``calculateMassMatrix`` fail.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

CHARACTERS = ["humanoid", "laikago", "atlas", "snake36", "snake72", "snake195"]
#: bodies PyBullet's joint API can drive (n_q <= 128); snake195 has 259 position coordinates
SIMULABLE = ["humanoid", "laikago", "atlas", "snake36", "snake72"]
REVOLUTE_ONLY = ["laikago", "atlas"]
GRAVITY = (0.0, -9.8, 0.0)


@dataclasses.dataclass
class World:
    """A character in its own client, with its model and workspace."""

    client: int
    character: Any
    model: Any
    data: Any
    limits: list  # (lower, upper) per movable joint, None for spherical / unlimited


def _make(name: str, fixed: bool) -> World:
    import pybullet as pb

    from jt_bullet.characters import load
    from toolkit.dynamics.model import Data

    c = pb.connect(pb.DIRECT)
    pb.setGravity(*GRAVITY, physicsClientId=c)
    ch = load(name, c, fixed_base=fixed, self_collision=False, base_position=(0.1, 2.0, -0.2))
    model = ch.model()
    limits = []
    for j in ch.joint_indices:
        info = pb.getJointInfo(ch.body_id, j, physicsClientId=c)
        lo, hi = info[8], info[9]
        limits.append((lo, hi) if info[2] != pb.JOINT_SPHERICAL and hi > lo else None)
    return World(c, ch, model, Data(model), limits)


def state_in_limits(w: World, rng: np.random.Generator, vel: float = 0.5) -> tuple:
    """Random ``(q, qd)`` with revolute joints strictly inside their limits."""
    m = w.model
    q, qd = m.random_state(rng, vel)
    if m.floating:
        q[0:3] = (0.1, 2.0, -0.2)
    for i, lim in enumerate(w.limits):
        b = i + 1
        if lim is None:
            continue
        lo, hi = lim
        span = hi - lo
        q[m.q_idx[b]] = rng.uniform(lo + 0.2 * span, hi - 0.2 * span)
        qd[m.v_idx[b]] = vel * min(1.0, span) * rng.normal()
    return q, qd
