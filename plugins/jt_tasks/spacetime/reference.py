"""The reference motion of ``task=spacetime``: any DeepMimic humanoid clip, sampled at any time.

``SpacetimeReference`` reads a clip of ``pybullet_data`` (``humanoid3d_<name>.txt``) or a path and
answers, at any clip time ``t`` (``sample``) or phase (``at_phase``):

* the pose ``q`` (root position, root quaternion, joints; slerp between frames) and the velocities
  ``qd``: *per-frame* central differences (``toolkit.motion.kinematics.clip_velocities``, whose
  neighbours across the loop seam come from the previous / next cycle) interpolated linearly
  between frames, so there is no spike at the seam of a looping clip (research notes, pitfalls);
* the whole-body CoM (world) and the four end effectors (ankle and wrist joint origins, relative
  to the ground-projected root, in the root's heading frame), per frame by PyBullet forward
  kinematics in ``toolkit.motion`` (never imported here), interpolated linearly;
* a looping clip repeats with the root shifted by ``Clip.cycle_offset()`` (vertical part zeroed)
  per cycle; a non-looping clip holds its last frame (zero velocities) after its end.

The heading frame turns about +y (y-up world): ``heading_axis`` x (the humanoid's forward axis)
or z (backflip, roll, crawl: x points up or down during the motion; authors' code).

The clip's feet dip a few cm into the ground in places: the whole reference is lifted by
``lift`` so that its lowest point over the clip is ``ground_clearance`` above the ground (ours).
"""

from __future__ import annotations

import bisect
import dataclasses
import math
import os
from typing import Optional

import numpy as np

from toolkit.motion import rotations as rot

#: end-effector links (PyBullet link index = joint index): right ankle, left ankle, right wrist, left wrist
END_EFFECTORS = (5, 11, 8, 14)
HEADING_AXES = {"x": np.array([1.0, 0.0, 0.0]), "z": np.array([0.0, 0.0, 1.0])}


def resolve_clip(name: str) -> str:
    """Path of a clip given as a path or a ``pybullet_data`` humanoid motion name (``run``).

    Raises:
        JtError: no such file (the message lists the shipped humanoid clips).
    """
    from toolkit.errors import JtError
    from toolkit.motion.skeletons import motions_dir

    d = motions_dir()
    name = str(name)
    for cand in (name, os.path.join(d, f"humanoid3d_{name}.txt"), os.path.join(d, name),
                 os.path.join(d, f"{name}.txt")):
        if os.path.isfile(cand):
            return cand
    known = sorted(f[len("humanoid3d_"):-4] for f in os.listdir(d) if f.startswith("humanoid3d_") and f.endswith(".txt"))
    raise JtError(f"task.clip={name!r}: no such clip; give a path or one of: {', '.join(known)}")


def load_humanoid_clip(name: str):
    """The ``Clip`` of ``name`` (``resolve_clip``); a one-line ``JtError`` for a file that is not a
    DeepMimic humanoid motion."""
    from toolkit.errors import JtError
    from toolkit.motion import ClipError, load_clip

    path = resolve_clip(name)
    try:
        clip = load_clip(path, "humanoid")
    except ClipError as e:
        raise JtError(f"task.clip={name!r}: not a DeepMimic humanoid motion: {e}") from None
    return clip


def heading_quat(q_root: np.ndarray, axis: str = "x") -> np.ndarray:
    """Rotation about +y ``(4,)`` that turns the rest direction of the root's ``axis`` into its
    current direction projected on the ground (y-up world)."""
    a = HEADING_AXES[axis]
    f = rot.quat_rotate(np.asarray(q_root, dtype=float), a)
    yaw = math.atan2(-f[2], f[0]) - math.atan2(-a[2], a[0])
    # quat_from_axis_angle((0, 1, 0), yaw) bit for bit (numpy's sin / cos on the same one-element
    # array, the unit axis's products kept, signed zeros included), without its general-case calls
    half = 0.5 * np.array([yaw])
    sn, cs = float(np.sin(half)[0]), float(np.cos(half)[0])
    return np.array([0.0 * sn, 1.0 * sn, 0.0 * sn, cs])


def heading_frame(root_q: np.ndarray, points: np.ndarray, axis: str = "x",
                  inv: Optional[np.ndarray] = None) -> np.ndarray:
    """``points (..., 3)`` relative to the ground-projected root ``root_q[:3]`` (height kept), in the
    root's heading frame; ``inv``: the heading's inverse ``(4,)`` if the caller has it already
    (``quat_conjugate(heading_quat(root_q[3:7], axis))``)."""
    x, _, z = root_q[:3].tolist() if isinstance(root_q, np.ndarray) else [float(v) for v in root_q[:3]]
    if inv is None:
        inv = rot.quat_conjugate(heading_quat(root_q[3:7], axis))
    pts = np.array(points, dtype=float)  # points - (x, 0, z), column by column (the same bits)
    pts[..., 0] -= x
    pts[..., 1] -= 0.0
    pts[..., 2] -= z
    return rot.quat_rotate(inv, pts)


@dataclasses.dataclass(frozen=True)
class RefState:
    """The reference at one clip time.

    Attributes:
        q: pose ``(n_q,)``; qd: velocities ``(n_dof,)`` (``toolkit.dynamics`` layout, root world).
        com: whole-body CoM ``(3,)`` (world); ee: end effectors ``(4, 3)`` in the heading frame.
        phase: clip phase in ``[0, 1]`` (1 after a non-looping clip's end).
    """

    q: np.ndarray
    qd: np.ndarray
    com: np.ndarray
    ee: np.ndarray
    phase: float


class SpacetimeReference:
    """A DeepMimic humanoid clip as a reference motion (see the module docstring).

    Args:
        clip: a ``pybullet_data`` humanoid clip name or a path.
        heading_axis: ``x`` or ``z``.
        ground_clearance: m, the lowest point of the clip after the lift (ours).
        loop: override the clip's own ``Loop`` flag (None: keep it; every shipped clip wraps).
    """

    def __init__(self, clip: str = "run", heading_axis: str = "x", ground_clearance: float = 0.0,
                 loop: Optional[bool] = None) -> None:
        from toolkit.errors import JtError
        from toolkit.motion.kinematics import KinematicBody, clip_velocities, forward_kinematics

        if heading_axis not in HEADING_AXES:
            raise JtError(f"task.heading_axis={heading_axis!r}: x or z")
        self.clip = load_humanoid_clip(clip)
        if loop is not None:
            self.clip = dataclasses.replace(self.clip, loop=bool(loop))
        self.heading_axis = heading_axis
        c = self.clip
        self.skeleton = c.skeleton
        self.loop = bool(c.loop)
        self.period = float(c.duration)
        self.offset = c.cycle_offset()
        vel = clip_velocities(c)
        self._vel = np.concatenate([vel.root_lin, vel.root_ang, vel.joints], axis=1)
        kin = forward_kinematics(c.skeleton, c.root_pos, c.root_rot, c.joints)
        body = KinematicBody(c.skeleton)
        try:
            self.masses = np.asarray(body.masses, dtype=float)
            low = min(body.lowest_point(np.concatenate([c.root_pos[i], c.root_rot[i], c.joints[i]]))
                      for i in range(c.n_frames))
        finally:
            body.close()
        self.lift = float(ground_clearance - low)
        m = self.masses
        self._com = (m[0] * c.root_pos + np.einsum("l,fld->fd", m[1:], kin.link_com)) / m.sum()
        self._com[:, 1] += self.lift
        self._ee = np.stack([heading_frame(np.concatenate([c.root_pos[i], c.root_rot[i]]),
                                           kin.joint_pos[i, list(END_EFFECTORS)], heading_axis)
                             for i in range(c.n_frames)])
        self._ee[:, :, 1] += self.lift
        self._times = [float(x) for x in c.times]
        self._slerp_tables()

    def _slerp_tables(self) -> None:
        """Per frame pair ``i``, what ``quat_slerp`` computes before the fraction enters: the start
        rotations ``(n_frames - 1, 1 + n_spherical, 4)`` (root, then every spherical joint,
        normalised) and the log of the shortest-arc rotation to the next frame ``(..., 3)``, each
        with the same calls on the same ``(1 + n_spherical, 4)`` rows as the slerp (bit for bit)."""
        c = self.clip
        sph = self.skeleton._conversion_columns()[1]  # (n_spherical, 4) quaternion columns
        self._sph = sph
        q0s, logs = [], []
        for i in range(c.n_frames - 1):
            q0 = rot.quat_normalize(np.vstack([c.root_rot[i], c.joints[i][sph]]))
            q1 = rot.quat_normalize(np.vstack([c.root_rot[i + 1], c.joints[i + 1][sph]]))
            q0s.append(q0)
            logs.append(rot.quat_to_expmap(rot.quat_canonical(rot.quat_relative(q0, q1))))
        self._slerp_q0, self._slerp_log = np.array(q0s), np.array(logs)
        self.offset = np.ascontiguousarray(self.offset, dtype=float)
        self._lift_vec = np.array([0.0, self.lift, 0.0])

    # ------------------------------------------------------------------ time
    def phase(self, t: float) -> float:
        """Clip phase of clip time ``t``: ``(t / T) % 1`` for a loop, ``clip(t / T, 0, 1)`` else."""
        x = float(t) / self.period
        return x % 1.0 if self.loop else min(max(x, 0.0), 1.0)

    def _locate(self, t: float) -> tuple[int, int, float, bool]:
        """``(cycle, frame, fraction, held)`` of clip time ``t``."""
        T = self.period
        if self.loop:
            k = math.floor(t / T)
            local = t - k * T
        else:
            k, local = 0, min(max(t, 0.0), T)
        times = self._times
        i = min(max(bisect.bisect_right(times, local) - 1, 0), len(times) - 2)  # np.searchsorted's
        frac = min(max((local - times[i]) / (times[i + 1] - times[i]), 0.0), 1.0)
        return int(k), i, frac, (not self.loop and t > T)

    def sample(self, t: float) -> RefState:
        """The reference at clip time ``t`` (s; any real number).

        The same bits as interpolating each frame pair from scratch (``quat_slerp`` of the root and
        every spherical joint, linear elsewhere): the slerp's fraction-free part comes from
        ``_slerp_tables``, the rest is ``kernels.sample``.
        """
        from jt_tasks.spacetime import kernels

        t = float(t)
        k, i, f, held = self._locate(t)
        c = self.clip
        q, qd = np.empty(7 + c.joints.shape[1]), np.empty(self._vel.shape[1])
        com, ee = np.empty(3), np.empty((4, 3))
        kernels.sample(i, f, k, held, self.lift, c.root_pos, c.joints, self._vel, self._com, self._ee,
                       self.offset, self._slerp_q0, self._slerp_log, self._sph, q, qd, com, ee)
        return RefState(q, qd, com, ee, self.phase(t))

    def at_phase(self, phase: float, cycle: int = 0) -> RefState:
        """The reference at ``phase`` of cycle ``cycle``."""
        return self.sample((float(phase) + int(cycle)) * self.period)
