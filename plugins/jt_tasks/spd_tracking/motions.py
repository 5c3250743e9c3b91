"""Reference motions for SPD tracking, in the simulator's generalised coordinates.

A reference gives the pose ``q(t)`` ``(n_q,)`` (root position, root quaternion x,y,z,w, then the
joints in model order, ``toolkit.dynamics`` layout) and the velocity ``qd(t)`` ``(n_dof,)`` by a
central difference on the manifold (root: world linear and angular velocity; spherical joints:
angular velocity in the child frame; revolute: angle rate), the layout ``BulletBody.reset`` and
the SPD backends take.

* ``ClipReference``: a DeepMimic clip (``toolkit.motion.load_clip``). Humanoid clips are y-up as
  jt's world. Laikago's ``laikago_walk.txt`` is z-up facing +y; it is turned into jt's y-up world
  facing +x by ``LAIKAGO_TO_WORLD`` (root position and orientation; joint angles unchanged).
* ``SnakeWave``: a generated slithering motion (thesis ``001`` Table 2.2 tracks a "slither" it
  does not specify). Joint ``i = 1..k`` turns about the vertical (its local y) by

      theta_i(t) = A sin(2 pi f t - 2 pi i / lambda)

  (a travelling wave from head to tail: amplitude ``A`` rad, frequency ``f`` Hz, ``lambda``
  segments per wavelength); the root segment (the head, the body trails along +x from it)
  moves at constant speed ``v`` along -x at height ``h`` with a fixed orientation.
"""

from __future__ import annotations

import dataclasses
import math
import os
from typing import Any

import numpy as np

from toolkit.motion import rotations as rot
from toolkit.errors import JtError

#: z-up, facing +y (laikago mocap) -> y-up, facing +x: -90 deg about x (z -> y), then -90 deg
#: about y (-z -> +x)
LAIKAGO_TO_WORLD = rot.quat_multiply(
    rot.quat_from_axis_angle([0.0, 1.0, 0.0], -math.pi / 2),
    rot.quat_from_axis_angle([1.0, 0.0, 0.0], -math.pi / 2))

HUMANOID_MOTIONS = ("walk", "run", "cartwheel", "backflip")  #: 001 Table 2.2's humanoid motions


class Reference:
    """A reference motion: poses and velocities in generalised coordinates, vectorised over time.

    Args:
        joint_dofs: DoFs of each movable joint in model order (3 spherical, 1 revolute).
        name: motion name.
        duration: length of one cycle in seconds.
    """

    H = 1e-4  #: half-width of the central difference for velocities (s)

    def __init__(self, joint_dofs: list[int], name: str, duration: float) -> None:
        self.joint_dofs = [int(n) for n in joint_dofs]
        self.name = name
        self.duration = float(duration)
        self.n_q = 7 + sum(4 if n == 3 else 1 for n in self.joint_dofs)
        self.n_dof = 6 + sum(self.joint_dofs)

    def poses(self, times: np.ndarray) -> np.ndarray:
        """Poses ``(n, n_q)`` at ``times`` ``(n,)``."""
        raise NotImplementedError

    def pose(self, t: float) -> np.ndarray:
        """Pose ``(n_q,)`` at time ``t``."""
        return self.poses(np.array([float(t)]))[0]

    def _bounds(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Difference interval ``(a, b)`` around each time (central by default)."""
        return times - self.H, times + self.H

    def velocities(self, times: np.ndarray) -> np.ndarray:
        """Velocities ``(n, n_dof)`` at ``times`` ``(n,)`` (difference of ``poses``)."""
        times = np.asarray(times, dtype=float).reshape(-1)
        a, b = self._bounds(times)
        return self.difference(self.poses(a), self.poses(b), b - a)

    def velocity(self, t: float) -> np.ndarray:
        """Velocity ``(n_dof,)`` at time ``t``."""
        return self.velocities(np.array([float(t)]))[0]

    def difference(self, q0: np.ndarray, q1: np.ndarray, dt: np.ndarray) -> np.ndarray:
        """Generalised velocities ``(n, n_dof)`` taking poses ``q0`` to ``q1`` ``(n, n_q)`` in
        ``dt`` ``(n,)`` seconds."""
        dt = np.asarray(dt, dtype=float).reshape(-1, 1)
        v = np.empty((q0.shape[0], self.n_dof))
        v[:, 0:3] = (q1[:, 0:3] - q0[:, 0:3]) / dt
        v[:, 3:6] = rot.quat_to_expmap(
            rot.quat_multiply(q1[:, 3:7], rot.quat_conjugate(q0[:, 3:7]))) / dt
        iq, iv = 7, 6
        for n in self.joint_dofs:
            if n == 3:
                v[:, iv:iv + 3] = rot.quat_to_expmap(
                    rot.quat_relative(q0[:, iq:iq + 4], q1[:, iq:iq + 4])) / dt
                iq += 4
            else:
                v[:, iv] = (q1[:, iq] - q0[:, iq]) / dt[:, 0]
                iq += 1
            iv += n
        return v


class ClipReference(Reference):
    """A DeepMimic clip as a reference (looping clips wrap and advance the root).

    Args:
        clip: a ``toolkit.motion.Clip``.
        joint_indices: the character's movable PyBullet joints in model order; must match the
            clip skeleton's joints.
        joint_dofs: their DoFs.
        to_world: quaternion x,y,z,w turning the data's world into jt's (identity for y-up data).
    """

    def __init__(self, clip: Any, joint_indices: list[int], joint_dofs: list[int],
                 to_world: np.ndarray | None = None) -> None:
        super().__init__(joint_dofs, clip.name, clip.duration)
        expected = [j.bullet_index for j in clip.skeleton.joints]
        if list(map(int, joint_indices)) != expected:
            raise JtError(f"clip {clip.name!r} ({clip.skeleton.name}) drives joints {expected}, "
                             f"the character has {list(joint_indices)}")
        self.clip = clip
        self.to_world = np.array([0.0, 0.0, 0.0, 1.0]) if to_world is None else np.asarray(to_world)
        p0, _, _ = clip.sample(0.0)
        # start over the world origin (laikago's data starts off-centre once turned)
        self._offset = -rot.quat_rotate(self.to_world, p0)
        self._offset[1] = 0.0

    def poses(self, times: np.ndarray) -> np.ndarray:
        p, r, j = self.clip.sample(np.asarray(times, dtype=float).reshape(-1))
        q = np.empty((p.shape[0], self.n_q))
        q[:, 0:3] = rot.quat_rotate(self.to_world, p) + self._offset
        q[:, 3:7] = rot.quat_normalize(rot.quat_multiply(self.to_world, r))
        q[:, 7:] = j
        return q

    def _bounds(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One-sided at a cycle's ends, so that the seam between the last frame and the next
        cycle's first (not equal in most files) is never differenced."""
        h, T = self.H, self.duration
        if self.clip.loop:
            k = np.where(times > 0, np.ceil(times / T) - 1.0, np.floor(times / T))
            local = times - k * T
        else:
            local = np.clip(times, 0.0, T)
        a = np.where(local - h < 0.0, times, times - h)
        b = np.where(local + h > T, times, times + h)
        return a, b


@dataclasses.dataclass
class WaveParams:
    """Travelling-wave slither (ours; the thesis gives no formula)."""

    amplitude: float = 0.3
    """A: joint amplitude about the vertical, rad."""
    frequency: float = 1.0
    """f: wave frequency, Hz."""
    wavelength: float = 10.0
    """lambda: segments per wavelength (phase lag 2 pi / lambda per joint)."""
    speed: float = 0.2
    """v: forward speed of the root (head) along -x, m/s."""
    height: float = 0.02
    """h: root height, m (half the segment width: resting on the ground)."""


class SnakeWave(Reference):
    """Generated slither for a snake of spherical joints (see the module docstring)."""

    def __init__(self, joint_dofs: list[int], params: WaveParams | None = None) -> None:
        if any(n != 3 for n in joint_dofs):
            raise ValueError("SnakeWave needs a chain of spherical joints")
        self.p = params or WaveParams()
        super().__init__(joint_dofs, "slither", 1.0 / self.p.frequency)
        self.k = len(joint_dofs)

    def poses(self, times: np.ndarray) -> np.ndarray:
        p = self.p
        t = np.asarray(times, dtype=float).reshape(-1, 1)
        q = np.zeros((t.shape[0], self.n_q))
        q[:, 0] = -p.speed * t[:, 0]
        q[:, 1] = p.height
        q[:, 6] = 1.0
        i = np.arange(1, self.k + 1)[None, :]
        theta = p.amplitude * np.sin(2 * math.pi * p.frequency * t - 2 * math.pi * i / p.wavelength)
        quats = np.zeros((t.shape[0], self.k, 4))
        quats[..., 1] = np.sin(0.5 * theta)
        quats[..., 3] = np.cos(0.5 * theta)
        q[:, 7:] = quats.reshape(t.shape[0], -1)
        return q


def motion_path(character: str, motion: str) -> str:
    """The DeepMimic file for ``motion`` of ``character`` in ``pybullet_data`` (or a path)."""
    from toolkit.motion import motions_dir

    if motion.endswith(".txt") or os.sep in motion:
        return motion
    prefix = {"humanoid": "humanoid3d_", "laikago": "laikago_"}.get(character)
    if prefix is None:
        raise JtError(f"no mocap for character {character!r}")
    path = os.path.join(motions_dir(), f"{prefix}{motion}.txt")
    if not os.path.exists(path):
        known = sorted(f[len(prefix):-4] for f in os.listdir(motions_dir())
                       if f.startswith(prefix) and f.endswith(".txt"))
        raise JtError(f"no motion {motion!r} for {character}; choose one of: {', '.join(known)}")
    return path


def default_motion(character: str) -> str:
    """``run`` (humanoid), ``walk`` (laikago), ``slither`` (snakes)."""
    if character.startswith("snake"):
        return "slither"
    return {"humanoid": "run", "laikago": "walk"}.get(character, "")


def make_reference(character: Any, motion: str, wave: WaveParams | None = None) -> Reference:
    """The reference for a loaded ``Character`` and a motion name (``auto``: the default).

    Raises:
        ValueError: no such motion for the character (the message lists the choices).
    """
    from toolkit.motion import load_clip

    name = character.name
    motion = default_motion(name) if motion in ("auto", "", None) else motion
    if not motion:
        raise JtError(f"no motion for character {name!r}: tracking supports humanoid "
                         "(mocap clips), laikago (walk) and the snakes (slither)")
    if motion == "slither":
        if not name.startswith("snake"):
            raise JtError(f"motion 'slither' is for the snakes, not {name!r}")
        return SnakeWave(character.joint_dofs, wave)
    if name.startswith("snake"):
        raise JtError(f"the snakes track the generated 'slither', not {motion!r}")
    clip = load_clip(motion_path(name, motion))
    to_world = LAIKAGO_TO_WORLD if clip.skeleton.up_axis == 2 else None
    return ClipReference(clip, character.joint_indices, character.joint_dofs, to_world)
