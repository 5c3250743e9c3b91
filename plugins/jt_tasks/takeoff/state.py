"""Take-off states (``000`` §3, §6.1.1): a frame of the DeepMimic run clip with imposed features.

The take-off state is "a time instant midway through the last support phase before becoming
airborne" (``000`` §3). We read it off ``humanoid3d_run.txt``: the support phases of the take-off
foot are the (circular) runs of frames whose ankle link sits within ``contact_tol`` of its lowest
height; the state is sampled at the middle of that run, velocities by central differences of the
clip. The explored features are then imposed in the *facing frame* (``000`` §6.1.1: "a
facing-direction invariant frame"): x = the root's heading projected on the ground, y = up,
z = x × y (the character's right for DeepMimic data):

* high jump: ``omega_x``, ``omega_z`` (root angular velocity), ``v_z`` (root linear velocity), with
  ``omega_y`` fixed to 3 rad/s (``000`` §6.1.1); the approach angle ``alpha`` rotates the suite
  (``jt_tasks.jumping.scene``), not the character;
* obstacle / long jump: ``omega_x``, ``omega_y``, ``omega_z``.

The other dimensions of the state stay those of the reference run (``000`` §8). The character is
placed with its root above the origin, the take-off foot's lowest point ``foot_clearance`` above
the ground, and its heading along world +x (the suite is built in this facing frame).
"""

from __future__ import annotations

import dataclasses
import os
from typing import Any, Optional

import numpy as np

from toolkit.motion import rotations as rot

FEATURE_NAMES = {"highjump": ("alpha", "omega_x", "omega_z", "v_z"),
                 "obstacle": ("omega_x", "omega_y", "omega_z")}
#: the link of each ankle by name (humanoid); the simulator (``Simulator.link_index``) or the
#: skeleton (``Skeleton.link_index``) turns it into an index where it is used
FOOT_LINKS = {"right": "right_ankle", "left": "left_ankle"}


@dataclasses.dataclass
class TakeoffState:
    """A simulator state at take-off and where it came from.

    Attributes:
        q: generalised positions ``(n_q,)`` (``toolkit.dynamics`` layout, root x,y,z then x,y,z,w).
        qd: generalised velocities ``(n_dof,)`` (root linear and angular velocity in world).
        time: clip time of the take-off instant (s).
        foot: ``"right"`` or ``"left"``: the take-off foot.
        features: the imposed feature values by name.
    """

    q: np.ndarray
    qd: np.ndarray
    time: float
    foot: str
    features: dict[str, float]


def heading_quat(q_root: np.ndarray) -> np.ndarray:
    """Rotation about +y ``(4,)`` x,y,z,w that turns +x into the root's heading (y-up world)."""
    fwd = rot.quat_rotate(q_root, np.array([1.0, 0.0, 0.0]))
    yaw = float(np.arctan2(-fwd[2], fwd[0]))
    return rot.quat_from_axis_angle(np.array([0.0, 1.0, 0.0]), yaw)


def support_phase_time(clip: Any, foot: str, contact_tol: float = 0.06) -> tuple[float, tuple[int, int]]:
    """Middle of the take-off foot's support phase in a clip (the last one, circularly for loops).

    Returns:
        ``(time, (first_frame, last_frame))`` of the support phase (frames may wrap around).
    """
    kin = clip.fk()
    h = kin.link_com[:, clip.skeleton.link_index(FOOT_LINKS[foot]), 1]
    stance = h < h.min() + contact_tol
    n = len(h)
    if stance.all():
        return float(clip.duration / 2), (0, n - 1)
    # rotate so that index 0 is a swing frame, then take the last stance run
    start = int(np.argmin(stance))
    order = [(start + i) % n for i in range(n)]
    runs, cur = [], []
    for i in order:
        if stance[i]:
            cur.append(i)
        elif cur:
            runs.append(cur)
            cur = []
    if cur:
        runs.append(cur)
    run = runs[-1]
    dt = float(np.mean(np.diff(clip.times)))
    t0 = clip.times[run[0]]
    t_mid = t0 + 0.5 * (len(run) - 1) * dt
    if clip.loop:
        t_mid = t_mid % clip.duration
    return float(t_mid), (run[0], run[-1])


def reference_state(clip: Any, t: float, h: float = 1.0 / 120.0) -> tuple[np.ndarray, ...]:
    """Pose and central-difference velocities of ``clip`` at time ``t``.

    Returns:
        ``root_pos (3,)``, ``root_rot (4,)``, ``joints (n_q_joints,)``, ``v (3,)``, ``w (3,)``
        (world), ``joint_vel (n_dof_joints,)`` (local angular velocities / angle rates).
    """
    sk = clip.skeleton
    p, r, j = clip.sample(np.array([t - h, t, t + h]))
    v = (p[2] - p[0]) / (2 * h)
    w = rot.quat_to_expmap(rot.quat_multiply(r[2], rot.quat_conjugate(r[0]))) / (2 * h)
    parts = []
    for spec, s in zip(sk.joints, sk.q_slices.values()):
        if spec.kind == "spherical":
            parts.append(rot.quat_to_expmap(rot.quat_multiply(rot.quat_conjugate(j[0][s]), j[2][s])) / (2 * h))
        else:
            parts.append((j[2][s] - j[0][s]) / (2 * h))
    return p[1], rot.quat_normalize(r[1]), j[1], v, w, np.concatenate(parts)


def impose(root_rot: np.ndarray, v: np.ndarray, w: np.ndarray, features: dict[str, float],
           omega_y: Optional[float], v_y: Optional[float] = None) -> tuple[np.ndarray, np.ndarray]:
    """World root velocities ``(v (3,), w (3,))`` with features imposed in the facing frame.

    ``v_y`` (not None) replaces the vertical root speed: the "jumping intention" (see
    ``takeoff_state``).
    """
    hq = heading_quat(root_rot)
    inv = rot.quat_conjugate(hq)
    v_f = rot.quat_rotate(inv, v)
    w_f = rot.quat_rotate(inv, w)
    for name, axis in (("omega_x", 0), ("omega_y", 1), ("omega_z", 2)):
        if name in features:
            w_f[axis] = features[name]
    if omega_y is not None and "omega_y" not in features:
        w_f[1] = omega_y
    if "v_z" in features:
        v_f[2] = features["v_z"]
    if v_y is not None:
        v_f[1] = float(v_y)
    return rot.quat_rotate(hq, v_f), rot.quat_rotate(hq, w_f)


_SUPPORT_TIMES: dict[tuple, float] = {}
"""``support_phase_time`` by (clip file, its mtime, foot, tolerance): a rollout worker builds 16 envs."""


def takeoff_state(features: dict[str, float], clip_name: str = "run", foot: str = "right",
                  omega_y: Optional[float] = 3.0, contact_tol: float = 0.06,
                  v_y: Optional[float] = None) -> TakeoffState:
    """The take-off state of ``clip_name`` with ``features`` imposed, heading along world +x.

    Args:
        features: feature values by name (``alpha`` is ignored here: it rotates the suite).
        clip_name: a DeepMimic humanoid clip (``humanoid3d_<name>.txt``) or a path.
        foot: take-off foot, ``right`` or ``left``.
        omega_y: fixed root angular velocity about up in the facing frame (high jump: 3 rad/s,
            ``000`` §6.1.1); None keeps the clip's.
        contact_tol: a foot within this height (m) of its lowest is on the ground.
        v_y: vertical root speed (m/s) imposed at take-off; None keeps the clip's (~0 at
            mid-support of a steady run). ``000`` §8: the authors' reference runs end in "a low
            in-place jump after the last running step" and "this jumping intention" is embedded
            in their take-off states; DeepMimic's steady run has none, so jt imposes it
            (``liftoff_vertical_speed`` of the jump clip gives the default, docs/highjump.md).

    Returns:
        The state; its root is above the origin and the foot clearance is applied by the env.
    """
    from toolkit.motion import load_clip
    from toolkit.motion.skeletons import motions_dir

    path = clip_name if os.path.sep in clip_name else os.path.join(motions_dir(), f"humanoid3d_{clip_name}.txt")
    clip = load_clip(path)
    key = (os.path.abspath(path), os.path.getmtime(path), foot, float(contact_tol))
    if key not in _SUPPORT_TIMES:  # the clip's forward kinematics: ~30 ms, once per process, not per env
        _SUPPORT_TIMES[key] = support_phase_time(clip, foot, contact_tol)[0]
    t = _SUPPORT_TIMES[key]
    p, r, j, v, w, jv = reference_state(clip, t)
    v, w = impose(r, v, w, features, omega_y, v_y)
    # turn the whole state about +y so the heading is +x, and put the root above the origin
    inv = rot.quat_conjugate(heading_quat(r))
    r = rot.quat_normalize(rot.quat_multiply(inv, r))
    v, w = rot.quat_rotate(inv, v), rot.quat_rotate(inv, w)
    q = np.concatenate([[0.0, p[1], 0.0], r, j])
    qd = np.concatenate([v, w, jv])
    return TakeoffState(q=q, qd=qd, time=t, foot=foot, features=dict(features))


def liftoff_vertical_speed(clip_name: str = "jump") -> float:
    """Largest vertical root speed (m/s) of a DeepMimic humanoid clip, by central differences.

    For ``humanoid3d_jump.txt`` (a standing jump) this is the root's speed at lift-off, 2.03 m/s:
    the source of the jumping tasks' default ``v_y``.
    """
    from toolkit.motion import load_clip
    from toolkit.motion.skeletons import motions_dir

    path = clip_name if os.path.sep in clip_name else os.path.join(motions_dir(), f"humanoid3d_{clip_name}.txt")
    clip = load_clip(path)
    h = 1.0 / 120.0
    times = np.linspace(h, clip.duration - h, 4 * len(clip.times))
    p = clip.sample(np.concatenate([times - h, times + h]))[0]
    n = len(times)
    return float(np.max((p[n:, 1] - p[:n, 1]) / (2 * h)))


def normalise_heading(q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The state turned about +y so that its heading is +x, its root above the origin.

    As ``takeoff_state`` builds its states (height kept; the jump env re-places the foot).
    Returns ``(q (n_q,), qd (n_dof,))``; joint coordinates and velocities are local and unchanged.
    """
    q, qd = np.asarray(q, dtype=float).copy(), np.asarray(qd, dtype=float).copy()
    inv = rot.quat_conjugate(heading_quat(q[3:7]))
    q[3:7] = rot.quat_normalize(rot.quat_multiply(inv, q[3:7]))
    q[0] = q[2] = 0.0
    qd[:3], qd[3:6] = rot.quat_rotate(inv, qd[:3]), rot.quat_rotate(inv, qd[3:6])
    return q, qd


def facing_velocities(q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Root linear and angular velocity ``(3,), (3,)`` in the facing frame of state ``(q, qd)``."""
    inv = rot.quat_conjugate(heading_quat(np.asarray(q[3:7])))
    return rot.quat_rotate(inv, np.asarray(qd[:3])), rot.quat_rotate(inv, np.asarray(qd[3:6]))
