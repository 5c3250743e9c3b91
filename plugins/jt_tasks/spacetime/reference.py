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
* a looping clip repeats cycle after cycle. With ``cycle_turn`` (default) cycle ``k`` is the clip
  moved by the ``k``-th power of the rigid ground-plane motion ``T`` that takes the first frame's
  root onto the last frame's (its yaw ``turn`` about +y and its shift): ``T(x) = R(turn) (x - p_0)
  + p_N`` on horizontal positions, ``R(turn)`` on the root rotation and the root velocities, so a
  character that tracks the clip's own steps keeps following its reference across the seam
  (walk 0.12 rad per cycle, run -0.09: for the walk a yaw jump in its data, see ``straighten``). Without it (the authors' code), each cycle
  is shifted by ``Clip.cycle_offset()`` only and the heading snaps back at every seam. A
  non-looping clip holds its last frame (zero velocities) after its end.
* ``straighten`` removes the root's yaw from every frame of a looping clip before any of this
  (each frame's root turned about +y to face as the first frame; pitch, roll, positions and joints
  kept), so the clip faces the way it travels and cycles neither turn nor snap. The shipped walk
  needs it: its root yaw falls 0 -> -0.13 rad over the first step, jumps back to 0 between frames
  18 and 19 (the second step is the first mirrored, yaw negated, but not offset) and ends at
  +0.12 rad, so the 0.12 rad "turn per cycle" is that jump, not a turn of the path (its root
  positions go straight along x); the authors' walk file has no root rotation at all.

The heading frame turns about +y (y-up world): ``heading_axis`` x (the humanoid's forward axis)
or z (backflip, roll, crawl: x points up or down during the motion; authors' code).

The reference is the clip as recorded: no lift (its feet dip a few cm into the ground in some
frames: 6.8 cm in one frame of the run). An episode's *start* is lifted only when it penetrates
the ground (``SpacetimeEnv``), as in the authors' code.
"""

from __future__ import annotations

import bisect
import dataclasses
import math
import os
from typing import Any, Optional

import numpy as np

from toolkit.motion import rotations as rot

#: end-effector links by name in the authors' bound-file order (their data/bounds readme, channels
#: 18-21); ``end_effector_links`` turns them into indices
END_EFFECTORS = ("right_ankle", "right_wrist", "left_ankle", "left_wrist")
HEADING_AXES = {"x": np.array([1.0, 0.0, 0.0]), "z": np.array([0.0, 0.0, 1.0])}


def end_effector_links(character: Any) -> tuple[int, ...]:
    """The link indices of ``END_EFFECTORS``, resolved once by their user.

    Args:
        character: anything with ``link_index(name)``: the simulator (``Simulator.link_index``)
            or a mocap skeleton (``Skeleton.link_index``, whose link order is the humanoid's
            PyBullet link indices).
    """
    return tuple(int(character.link_index(name)) for name in END_EFFECTORS)


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


def clip_turn(clip: Any, axis: str = "x") -> float:
    """Rad, the heading change about +y from a clip's first frame to its last (in ``(-pi, pi]``)."""
    yaw = [2.0 * math.atan2(h[1], h[3]) for h in (heading_quat(clip.root_rot[i], axis) for i in (0, -1))]
    return float(math.remainder(yaw[1] - yaw[0], 2.0 * math.pi))


def straightened(clip: Any, axis: str = "x") -> Any:
    """``clip`` with its root's yaw removed: every frame's root rotation turned about +y so that its
    heading (``heading_quat``) is the first frame's; positions and joints unchanged."""
    q = np.asarray(clip.root_rot, dtype=float)
    h = np.array([heading_quat(q[i], axis) for i in range(len(q))])  # (n_frames, 4) x y z w
    yaw = rot.quat_multiply(np.broadcast_to(h[0], h.shape), rot.quat_conjugate(h))
    return dataclasses.replace(clip, root_rot=rot.quat_multiply(yaw, q))


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
        loop: override the clip's own ``Loop`` flag (None: keep it; every shipped clip wraps).
        cycle_turn: carry the clip's heading change per cycle into the next cycles (module docstring).
        straighten: remove the root's yaw from every frame of a looping clip first (module docstring).

    Attributes:
        turn: rad, the heading change over one cycle (last frame minus first; 0 for a non-looping
            clip or without ``cycle_turn``).
        lowest: m, ``(n_frames,)`` the lowest point of each frame's pose (link bounding boxes).
    """

    def __init__(self, clip: str = "run", heading_axis: str = "x", loop: Optional[bool] = None,
                 cycle_turn: bool = True, straighten: bool = False) -> None:
        from toolkit.errors import JtError
        from toolkit.motion.kinematics import clip_velocities, forward_kinematics, kinematic_body

        if heading_axis not in HEADING_AXES:
            raise JtError(f"task.heading_axis={heading_axis!r}: x or z")
        self.clip = load_humanoid_clip(clip)
        if loop is not None:
            self.clip = dataclasses.replace(self.clip, loop=bool(loop))
        self.heading_axis = heading_axis
        if straighten and self.clip.loop:
            self.clip = straightened(self.clip, heading_axis)
        c = self.clip
        self.skeleton = c.skeleton
        self.loop = bool(c.loop)
        self.period = float(c.duration)
        self.offset = c.cycle_offset()
        vel = clip_velocities(c)
        self._vel = np.concatenate([vel.root_lin, vel.root_ang, vel.joints], axis=1)
        kin = forward_kinematics(c.skeleton, c.root_pos, c.root_rot, c.joints)
        body = kinematic_body(c.skeleton)
        try:
            self.masses = np.asarray(body.masses, dtype=float)
            self.lowest = np.array([body.lowest_point(np.concatenate([c.root_pos[i], c.root_rot[i], c.joints[i]]))
                                    for i in range(c.n_frames)])
        finally:
            body.close()
        m = self.masses
        self._com = (m[0] * c.root_pos + np.einsum("l,fld->fd", m[1:], kin.link_com)) / m.sum()
        ee = list(end_effector_links(c.skeleton))
        self._ee = np.stack([heading_frame(np.concatenate([c.root_pos[i], c.root_rot[i]]),
                                           kin.joint_pos[i, ee], heading_axis)
                             for i in range(c.n_frames)])
        self._times = [float(x) for x in c.times]
        self.turn = 0.0
        if self.loop and cycle_turn:
            self.turn = clip_turn(c, heading_axis)
        self._p0 = np.array([c.root_pos[0, 0], 0.0, c.root_pos[0, 2]])
        self._cycles: dict[int, np.ndarray] = {0: self._p0.copy()}
        if self.turn != 0.0:
            self._seam_velocities()
        self._slerp_tables()

    def _turned(self, k: int, pos: np.ndarray, quat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A first-cycle root position ``(3,)`` and rotation ``(4,)`` moved into cycle ``k``."""
        a = k * self.turn
        d = pos - self._p0
        o = self.cycle_origin(k)
        p = np.array([math.cos(a) * d[0] + math.sin(a) * d[2] + o[0], pos[1],
                      -math.sin(a) * d[0] + math.cos(a) * d[2] + o[2]])
        yaw = np.array([0.0, math.sin(0.5 * a), 0.0, math.cos(0.5 * a)])
        return p, rot.quat_multiply(yaw, quat)

    def _seam_velocities(self) -> None:
        """The root velocities of the first and last frame from their neighbours in the turned
        previous / next cycle (``clip_velocities`` takes them from a shifted, unturned one)."""
        c, t = self.clip, self.clip.times
        p_prev, r_prev = self._turned(-1, c.root_pos[-2], c.root_rot[-2])
        p_next, r_next = self._turned(1, c.root_pos[1], c.root_rot[1])
        for row, (pa, ra, pb, rb, dt) in enumerate([
                (p_prev, r_prev, c.root_pos[1], c.root_rot[1], t[1] + (t[-1] - t[-2])),
                (c.root_pos[-2], c.root_rot[-2], p_next, r_next, (t[-1] + t[1] - t[0]) - t[-2])]):
            i = 0 if row == 0 else -1
            self._vel[i, :3] = (pb - pa) / dt
            self._vel[i, 3:6] = rot.quat_to_expmap(rot.quat_multiply(rb, rot.quat_conjugate(ra))) / dt

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

    def cycle_origin(self, k: int) -> np.ndarray:
        """Where cycle ``k`` puts the first frame's root on the ground plane ``(3,)`` (y = 0):
        ``T^k(p_0)``; with no turn ``p_0 + k offset``."""
        k = int(k)
        got = self._cycles.get(k)
        if got is not None:
            return got
        step = 1 if k > 0 else -1
        j = 0
        while j + step in self._cycles:
            j += step
        c = self._cycles[j]
        while j != k:  # c_{j+1} = c_j + R(j turn) offset; c_{j-1} = c_j - R((j-1) turn) offset
            a = (j if step > 0 else j - 1) * self.turn
            off = np.array([math.cos(a) * self.offset[0] + math.sin(a) * self.offset[2], 0.0,
                            -math.sin(a) * self.offset[0] + math.cos(a) * self.offset[2]])
            c = c + step * off
            j += step
            self._cycles[j] = c
        return c

    # ------------------------------------------------------------------ time
    def phase(self, t: float) -> float:
        """Clip phase of clip time ``t``: ``(t / T) % 1`` for a loop, ``clip(t / T, 0, 1)`` else."""
        x = float(t) / self.period
        return x % 1.0 if self.loop else min(max(x, 0.0), 1.0)

    def cycle_yaw(self, t: float) -> float:
        """Rad, the yaw about the up axis by which the cycle of clip time ``t`` is turned from the
        first (``k turn``; 0 without ``cycle_turn`` or for a clip that does not loop)."""
        return self._locate(t)[0] * self.turn

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
        a = k * self.turn
        kernels.sample(i, f, held, math.cos(a), math.sin(a), self._p0, self.cycle_origin(k), c.root_pos, c.joints,
                       self._vel, self._com, self._ee, self._slerp_q0, self._slerp_log, self._sph, q, qd, com, ee)
        return RefState(q, qd, com, ee, self.phase(t))

    def at_phase(self, phase: float, cycle: int = 0) -> RefState:
        """The reference at ``phase`` of cycle ``cycle``."""
        return self.sample((float(phase) + int(cycle)) * self.period)
