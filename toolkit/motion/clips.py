"""DeepMimic-format mocap clips: loading, sampling, resampling, looping and mirroring.

A DeepMimic file is JSON with ``"Loop"`` (``"wrap"`` or ``"none"``) and ``"Frames"``; each frame
is ``[duration, root pos (3), root quat (4), joint values ...]`` where ``duration`` is the time
to the next frame. Humanoid files store every quaternion w-first; the loader converts them to
``x, y, z, w`` here, once, and normalises them (some shipped files are up to 40 % off unit norm).
Laikago files store the root quaternion x-first already and joint angles in a mocap convention
that the loader maps to URDF angles (see ``skeletons.LAIKAGO``). The world stays as in the data:
y-up for the humanoid (it faces +x, its right is +z), z-up for Laikago.
"""

from __future__ import annotations

import dataclasses
import json
import os
from typing import Sequence

import numpy as np

from toolkit.motion import rotations as rot
from toolkit.motion.skeletons import HUMANOID, LAIKAGO, SKELETONS, SPHERICAL, Skeleton


class ClipError(ValueError):
    """A mocap file that cannot be read: the message is one line naming the file and the problem."""


@dataclasses.dataclass(eq=False)
class Clip:
    """A motion clip in jt's conventions.

    Attributes:
        name: clip name (file stem without the ``humanoid3d_`` prefix).
        skeleton: the character's joint table.
        times: frame times from 0, strictly increasing ``(n_frames,)``.
        root_pos: root position in the world ``(n_frames, 3)``.
        root_rot: root orientation ``x, y, z, w`` ``(n_frames, 4)``.
        joints: internal joints in the quaternion layout ``(n_frames, skeleton.n_q)``.
        loop: whether the clip wraps (the last frame is the first pose of the next cycle).
        source: path the clip was read from ("" if built in memory).
        mirrored: whether this is the left/right mirror of the source.
    """

    name: str
    skeleton: Skeleton
    times: np.ndarray
    root_pos: np.ndarray
    root_rot: np.ndarray
    joints: np.ndarray
    loop: bool
    source: str = ""
    mirrored: bool = False

    @property
    def n_frames(self) -> int:
        return int(self.times.shape[0])

    @property
    def duration(self) -> float:
        """Length of one cycle in seconds (time of the last frame)."""
        return float(self.times[-1])

    @property
    def fps(self) -> float:
        """Mean frame rate in Hz."""
        return (self.n_frames - 1) / self.duration

    def joint(self, name: str) -> np.ndarray:
        """One joint's columns ``(n_frames, 4)`` (spherical) or ``(n_frames, 1)`` (revolute)."""
        return self.joints[:, self.skeleton.q_slices[name]]

    def cycle_offset(self) -> np.ndarray:
        """Root translation per cycle ``(3,)``: last minus first root position, zero along up
        (as DeepMimic's kinematic character does), zero for non-looping clips."""
        if not self.loop:
            return np.zeros(3)
        d = self.root_pos[-1] - self.root_pos[0]
        d[self.skeleton.up_axis] = 0.0
        return d

    # ----------------------------------------------------------------- sampling
    def sample(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pose at times ``t`` ``(...)``: slerp for quaternions, linear for the rest.

        A looping clip wraps around and shifts the root by ``cycle_offset()`` per cycle (also
        for negative times); cycle ``k`` covers ``(k T, (k+1) T]`` for positive times, so
        ``sample(times)`` returns the frames themselves. A non-looping clip is clamped to
        ``[0, duration]``.

        Returns:
            root_pos ``(..., 3)``, root_rot ``(..., 4)``, joints ``(..., n_q)``.
        """
        t = np.asarray(t, dtype=np.float64)
        T = self.duration
        if self.loop:
            # cycle k covers (kT, (k+1)T] for t > 0, so every frame time in [0, T] returns its
            # own frame (the seam between the last frame and the next cycle's first is the data's)
            cycles = np.where(t > 0, np.ceil(t / T) - 1.0, np.floor(t / T))
            local = t - cycles * T
        else:
            cycles = np.zeros_like(t)
            local = np.clip(t, 0.0, T)
        i = np.clip(np.searchsorted(self.times, local, side="right") - 1, 0, self.n_frames - 2)
        frac = np.clip((local - self.times[i]) / (self.times[i + 1] - self.times[i]), 0.0, 1.0)
        f = frac[..., None]
        root_pos = (1 - f) * self.root_pos[i] + f * self.root_pos[i + 1]
        root_pos = root_pos + cycles[..., None] * self.cycle_offset()
        root_rot = rot.quat_slerp(self.root_rot[i], self.root_rot[i + 1], frac)
        a, b = self.joints[i], self.joints[i + 1]
        joints = (1 - f) * a + f * b
        for j, s in zip(self.skeleton.joints, self.skeleton.q_slices.values()):
            if j.kind == SPHERICAL:
                joints[..., s] = rot.quat_slerp(a[..., s], b[..., s], frac)
        return root_pos, root_rot, joints

    def sample_phase(self, phase) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pose at phase ``phase`` ``(...)`` in ``[0, 1]`` of a cycle (``002`` §4.2's FFC lookup)."""
        return self.sample(np.asarray(phase, dtype=np.float64) * self.duration)

    def resample(self, rate: float) -> "Clip":
        """The clip sampled at ``rate`` Hz.

        Non-looping clips get frames at ``k / rate`` for ``k / rate <= duration``. Looping clips
        keep their exact cycle: ``round(duration * rate)`` equal intervals, so the rate is within
        half a frame of ``rate`` and the last frame is still the next cycle's first pose.
        """
        if not rate > 0:
            raise ValueError(f"resample rate must be positive, got {rate}")
        T = self.duration
        if self.loop:
            times = np.linspace(0.0, T, max(1, int(round(T * rate))) + 1)
        else:
            times = np.arange(int(np.floor(T * rate + 1e-9)) + 1) / rate
            if times.shape[0] < 2:
                times = np.array([0.0, T])
        root_pos, root_rot, joints = self.sample(times)
        return dataclasses.replace(self, times=times, root_pos=root_pos, root_rot=root_rot, joints=joints)

    def mirror(self) -> "Clip":
        """Left/right mirror: swap left and right joints and reflect across the plane through the
        origin normal to the lateral axis (z for the humanoid: its sagittal plane at rest)."""
        sk, k = self.skeleton, self.skeleton.lateral_axis
        root_pos = self.root_pos.copy()
        root_pos[:, k] = -root_pos[:, k]
        return dataclasses.replace(
            self, root_pos=root_pos, root_rot=sk.reflect_quat(self.root_rot),
            joints=sk.mirror_joints(self.joints), mirrored=not self.mirrored,
        )  # fmt: skip

    def velocities(self):
        """Finite-difference velocities; see ``toolkit.motion.kinematics.clip_velocities``."""
        from toolkit.motion.kinematics import clip_velocities

        return clip_velocities(self)

    def fk(self):
        """Link positions and orientations of every frame; see ``kinematics.forward_kinematics``."""
        from toolkit.motion.kinematics import forward_kinematics

        return forward_kinematics(self.skeleton, self.root_pos, self.root_rot, self.joints)


# --------------------------------------------------------------------------- loading


def _guess_skeleton(path: str, frames: list) -> Skeleton:
    base = os.path.basename(path)
    if base.startswith("humanoid"):
        return HUMANOID
    if base.startswith("laikago"):
        return LAIKAGO
    first = frames[0] if frames and isinstance(frames[0], list) else []
    for sk in SKELETONS.values():
        if len(first) == sk.frame_size:
            return sk
    sizes = ", ".join(f"{s.frame_size} ({s.name})" for s in SKELETONS.values())
    raise ClipError(f"{path}: cannot tell the skeleton: first frame has {len(first)} values, expected one of {sizes}")


def load_clip(path: str | os.PathLike, skeleton: Skeleton | str | None = None) -> Clip:
    """Read a DeepMimic-format clip.

    Args:
        path: the ``.txt`` (JSON) file.
        skeleton: ``HUMANOID``, ``LAIKAGO`` or their names; guessed from the file name
            (``humanoid*`` / ``laikago*``) or the frame length when omitted.

    Raises:
        ClipError: unreadable file, bad JSON, a missing key, a bad ``Loop`` value, fewer than two
            frames, a frame of the wrong length or with non-numbers, NaN/inf, non-positive frame
            durations, or a zero quaternion.
    """
    path = os.fspath(path)
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except OSError as e:
        raise ClipError(f"{path}: cannot read: {e.strerror or e}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise ClipError(f"{path}: bad JSON: {e}") from None
    if not isinstance(data, dict):
        raise ClipError(f"{path}: top level is {type(data).__name__}, expected an object")
    for key in ("Loop", "Frames"):
        if key not in data:
            raise ClipError(f"{path}: missing key {key!r}")
    loop_val = data["Loop"]
    loops = {"wrap": True, "none": False, True: True, False: False}
    if not isinstance(loop_val, (str, bool)) or loop_val not in loops:
        raise ClipError(f"{path}: 'Loop' is {loop_val!r}, expected 'wrap' or 'none'")
    frames = data["Frames"]
    if not isinstance(frames, list) or len(frames) < 2:
        n = len(frames) if isinstance(frames, list) else type(frames).__name__
        raise ClipError(f"{path}: 'Frames' must be a list of at least 2 frames, got {n}")
    sk = SKELETONS[skeleton] if isinstance(skeleton, str) else skeleton or _guess_skeleton(path, frames)
    for i, fr in enumerate(frames):
        if not isinstance(fr, list) or len(fr) != sk.frame_size:
            n = len(fr) if isinstance(fr, list) else type(fr).__name__
            raise ClipError(f"{path}: frame {i} has {n} values, expected {sk.frame_size} for {sk.name}")
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in fr):
            raise ClipError(f"{path}: frame {i} holds a non-number")
    arr = np.asarray(frames, dtype=np.float64)
    bad = np.argwhere(~np.isfinite(arr))
    if bad.size:
        raise ClipError(f"{path}: non-finite value at frame {bad[0][0]}, column {bad[0][1]}")
    durations = arr[:-1, 0]
    if np.any(durations <= 0):
        i = int(np.argmax(durations <= 0))
        raise ClipError(f"{path}: frame {i} has duration {durations[i]}, expected > 0")

    times = np.concatenate([[0.0], np.cumsum(durations)])
    root_pos = arr[:, 1:4].copy()
    root_rot = arr[:, 4:8] if sk.root_quat_order == "xyzw" else arr[:, [5, 6, 7, 4]]
    joints = arr[:, 8:].copy()
    quats = [("root", root_rot)]
    for j, s in zip(sk.joints, sk.q_slices.values()):
        if j.kind == SPHERICAL:
            joints[:, s] = joints[:, [s.start + 1, s.start + 2, s.start + 3, s.start]]  # w-first → xyzw
            quats.append((j.name, joints[:, s]))
        else:
            joints[:, s] = j.file_direction * joints[:, s] + j.file_offset
    for name, q in quats:
        norms = np.linalg.norm(q, axis=1)
        if np.any(norms < 1e-6):
            raise ClipError(f"{path}: zero quaternion for {name} at frame {int(np.argmax(norms < 1e-6))}")
    root_rot = rot.align_hemisphere(rot.quat_normalize(root_rot))
    for j, s in zip(sk.joints, sk.q_slices.values()):
        if j.kind == SPHERICAL:
            joints[:, s] = rot.align_hemisphere(rot.quat_normalize(joints[:, s]))
    name = os.path.splitext(os.path.basename(path))[0]
    name = name[len("humanoid3d_"):] if name.startswith("humanoid3d_") else name
    return Clip(name, sk, times, root_pos, root_rot, joints, loops[loop_val], source=path)


def load_humanoid_clips(names: Sequence[str] | None = None) -> list[Clip]:
    """All (or the named) ``humanoid3d_*`` clips shipped with ``pybullet_data``, sorted by name."""
    from toolkit.motion.skeletons import humanoid_clip_paths

    clips = [load_clip(p) for p in humanoid_clip_paths()]
    if names is None:
        return clips
    known = {c.name: c for c in clips}
    missing = [n for n in names if n not in known]
    if missing:
        raise KeyError(f"unknown humanoid clips {missing}; known: {sorted(known)}")
    return [known[n] for n in names]
