"""The regulariser of spacetime bounds' style runs (``002`` §3.3, eqs 7-8): ``spacetime_reg``.

``r_reg = exp(−Σ_i w_i a_i / β_i)`` (eq 7) penalises large kinetic energy, body linear
accelerations and joint angular accelerations; the style run's reward is ``r_s · r_reg`` (eq 8;
``task.style`` multiplies its terms, so listing ``spacetime_reg`` beside a style term is eq 8).
The paper leaves the weights and scales open; they follow the authors' code (``spacetime_reg``
env; research notes), the mean of four group means::

    r_reg = exp(−mean(E / β_E, |a_com,y| / β_com, mean_b |a_b − a_com| / β_b, mean_j |α_j| / β_j))

* ``E`` the kinetic energy (``toolkit.motion.style.kinetic_energy``: bodies' translational energy less
  the horizontal CoM part, as eq 4), ``a_com,y`` the vertical CoM acceleration, ``a_b`` each
  body's CoM acceleration (base and links), ``α_j`` each internal joint's angular acceleration
  (norm over its dofs; the fixed wrists have none). Accelerations by differences of the control
  step's velocities (the record's ``link_acc`` ``(n_bodies, 3)`` and ``joint_acc`` ``(n_dof,)``,
  written by ``task=spacetime``'s env).
* Each ``β`` is the reference clip's statistic bound ``min(max, Q3 + 1.5 IQR)`` over its frames
  times a scale: 16 (energy), 16 (CoM), 40 (bodies), and ``(β + 0.1) · 400`` for the joints
  (authors' code). The clip's statistics use its own frames: body CoMs by PyBullet forward
  kinematics, velocities and accelerations by ``numpy.gradient`` over the frame times, joint
  velocities by ``toolkit.motion.kinematics.clip_velocities``.

The clip is the term's ``clip``, else the record's ``clip`` (``task=spacetime``'s env writes its own).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import Any, Optional

import numpy as np

from jt_rewards.base import RecordTerm
from toolkit.motion.style import kinetic_energy


def upper_bound(x: np.ndarray) -> np.ndarray:
    """``min(max, Q3 + 1.5 IQR)`` per column of ``x`` ``(n_frames, ...)`` (authors' code)."""
    x = np.asarray(x, dtype=float)
    q1, q3 = np.percentile(x, [25, 75], axis=0)
    return np.minimum(x.max(axis=0), q3 + 1.5 * (q3 - q1))


def clip_statistics(clip: str) -> dict[str, np.ndarray]:
    """Per-frame statistics of a humanoid clip (name or path): ``energy`` ``(F,)`` J, ``com_acc_y``
    ``(F,)`` m/s² (absolute), ``body_acc`` ``(F, n_bodies)`` m/s² (``|a_b − a_com|``), ``joint_acc``
    ``(F, n_joints)`` rad/s² (internal joints with dofs)."""
    from toolkit.motion import load_clip
    from toolkit.motion.kinematics import clip_velocities, forward_kinematics, kinematic_body
    from toolkit.motion.skeletons import motions_dir

    import os

    path = clip if os.path.isfile(str(clip)) else os.path.join(motions_dir(), f"humanoid3d_{clip}.txt")
    if not os.path.isfile(path):
        from toolkit.errors import JtError

        known = sorted(f[len("humanoid3d_"):-4] for f in os.listdir(motions_dir()) if f.startswith("humanoid3d_"))
        raise JtError(f"spacetime_reg.clip={clip!r}: no such clip; give a path or one of: {', '.join(known)}")
    c = load_clip(path, "humanoid")
    kin = forward_kinematics(c.skeleton, c.root_pos, c.root_rot, c.joints)
    body = kinematic_body(c.skeleton)
    try:
        masses = np.asarray(body.masses, dtype=float)
    finally:
        body.close()
    t = np.asarray(c.times, dtype=float)
    pos = np.concatenate([c.root_pos[:, None], kin.link_com], axis=1)  # (F, n_bodies, 3)
    vel = np.gradient(pos, t, axis=0)
    acc = np.gradient(vel, t, axis=0)
    com_acc = np.einsum("b,fbd->fd", masses, acc) / masses.sum()
    energy = np.array([kinetic_energy(v, masses) for v in vel])
    jvel = clip_velocities(c).joints
    jacc = np.gradient(jvel, t, axis=0)
    return {"energy": energy, "com_acc_y": np.abs(com_acc[:, 1]),
            "body_acc": np.linalg.norm(acc - com_acc[:, None], axis=2),
            "joint_acc": joint_norms(c.skeleton, jacc)}


def joint_norms(skeleton: Any, dofs: np.ndarray) -> np.ndarray:
    """Norm per internal joint with dofs ``(..., n_joints)`` of a dof-layout array ``(..., n_dof)``."""
    dofs = np.asarray(dofs, dtype=float)
    return np.stack([np.linalg.norm(dofs[..., s], axis=-1) for s in skeleton.dof_slices.values()
                     if s.stop > s.start], axis=-1)


@functools.lru_cache(maxsize=16)
def clip_betas(clip: str, e_scale: float = 16.0, com_scale: float = 16.0, body_scale: float = 40.0,
               joint_scale: float = 400.0, joint_offset: float = 0.1) -> tuple:
    """``(β_E, β_com, β_b (n_bodies,), β_j (n_joints,))`` of a clip (see the module docstring)."""
    s = clip_statistics(clip)
    return (float(upper_bound(s["energy"])) * e_scale, float(upper_bound(s["com_acc_y"])) * com_scale,
            upper_bound(s["body_acc"]) * body_scale, (upper_bound(s["joint_acc"]) + joint_offset) * joint_scale)


class SpacetimeReg(RecordTerm):
    """Eq 7 regulariser ``exp(−Σ w_i a_i / β_i)`` in ``(0, 1]`` with β's from a reference clip.

    Record keys:
        ``link_vel``, ``link_acc`` ``(n_bodies, 3)`` (base first), ``masses`` ``(n_bodies,)``,
        ``joint_acc`` ``(n_dof,)`` (internal dofs, the ``toolkit.dynamics`` layout), ``clip``
        (unless the config names one).
    """

    @classmethod
    def needs(cls, params: Any) -> set[str]:
        """The link velocities and accelerations, masses, joint accelerations, and the record's
        ``clip`` unless the term names its own."""
        clip = params.get("clip") if hasattr(params, "get") else getattr(params, "clip", None)
        return {"link_vel", "link_acc", "masses", "joint_acc"} | (set() if clip is not None else {"clip"})


    @dataclasses.dataclass
    class Config:
        clip: Optional[str] = None
        """Reference clip (name or path) whose statistics give the β's; null: the record's ``clip`` (task=spacetime: its own)."""
        e_scale: float = 16.0
        """β_E = bound of the clip's energy × this (002 eq 7; authors' code)."""
        com_scale: float = 16.0
        """β_com = bound of its vertical CoM acceleration × this (authors' code)."""
        body_scale: float = 40.0
        """β_b = bound of each body's acceleration relative to the CoM × this (authors' code)."""
        joint_scale: float = 400.0
        """β_j = (bound of each joint's angular acceleration + joint_offset) × this (authors' code)."""
        joint_offset: float = 0.1
        """Rad/s² (authors' code)."""

        def check(self) -> None:
            from toolkit.schema import finite, require

            for k in ("e_scale", "com_scale", "body_scale", "joint_scale"):
                v = getattr(self, k)
                require(finite(v) and v > 0, f"spacetime_reg.{k}", v, "must be > 0")
            require(finite(self.joint_offset) and self.joint_offset >= 0, "spacetime_reg.joint_offset",
                    self.joint_offset, "must be >= 0")

    def betas(self, record: dict[str, Any]) -> tuple:
        """The β's of the term's clip (or the record's ``clip``), cached per clip."""
        p = self.params
        clip = p.clip if p.clip is not None else self.get(record, "clip")
        return clip_betas(str(clip), p.e_scale, p.com_scale, p.body_scale, p.joint_scale, p.joint_offset)

    def terms(self, record: dict[str, Any]) -> np.ndarray:
        """The four group penalties ``(4,)``: energy, vertical CoM, bodies, joints (each a / β)."""
        from toolkit.motion.skeletons import HUMANOID

        b_e, b_c, b_b, b_j = self.betas(record)
        masses = np.asarray(self.get(record, "masses"), dtype=float)
        acc = np.asarray(self.get(record, "link_acc"), dtype=float).reshape(-1, 3)
        com_acc = masses @ acc / masses.sum()
        e = kinetic_energy(self.get(record, "link_vel"), masses)
        body = np.linalg.norm(acc - com_acc, axis=1) / b_b
        joint = joint_norms(HUMANOID, self.get(record, "joint_acc")) / b_j
        return np.array([e / b_e, abs(com_acc[1]) / b_c, body.mean(), joint.mean()])

    def __call__(self, record: dict[str, Any]) -> float:
        r = math.exp(-float(self.terms(record).mean()))
        return r if math.isfinite(r) else 0.0
