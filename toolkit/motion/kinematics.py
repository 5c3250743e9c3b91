"""Velocities (finite differences) and forward kinematics of mocap poses.

Forward kinematics needs a physics engine's reading of the character's URDF: it comes from the
registered simulator that provides it (the optional ``Simulator`` hooks ``forward_kinematics``,
``kinematic_body`` and ``render_poses``, found by ``engine``); nothing here imports an engine.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Any

import numpy as np

from toolkit.motion import rotations as rot
from toolkit.motion.skeletons import SPHERICAL, Skeleton

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.motion.clips import Clip


@dataclasses.dataclass
class Velocities:
    """Velocities at a clip's frames.

    Attributes:
        root_lin: root linear velocity in the world frame ``(n_frames, 3)``.
        root_ang: root angular velocity in the world frame ``(n_frames, 3)``.
        joints: joint velocities in the dof layout ``(n_frames, n_dof)``: a spherical joint's
            angular velocity in its child (local) frame, as PyBullet's ``resetJointStatesMultiDof``
            and DeepMimic's ``ComputeAngVelRel`` use; a revolute joint's angle rate.
    """

    root_lin: np.ndarray
    root_ang: np.ndarray
    joints: np.ndarray


def clip_velocities(clip: "Clip") -> Velocities:
    """Central differences between the neighbouring frames of every frame.

    At the ends a looping clip takes its neighbours from the previous / next cycle (via
    ``Clip.sample``, root shifted by the cycle offset); a non-looping clip uses one-sided
    differences. Rotations are differenced on the group: ``log(q_next q_prev^-1) / dt`` (world)
    for the root, ``log(q_prev^-1 q_next) / dt`` (local) for joints, exact for constant angular
    velocity up to ``pi`` per two frames.
    """
    t = clip.times
    n = clip.n_frames
    idx_prev = np.concatenate([[0], np.arange(n - 1)])
    idx_next = np.concatenate([np.arange(1, n), [n - 1]])
    t_prev, t_next = t[idx_prev].copy(), t[idx_next].copy()
    pp, rp, jp = clip.root_pos[idx_prev].copy(), clip.root_rot[idx_prev].copy(), clip.joints[idx_prev].copy()
    pn, rn, jn = clip.root_pos[idx_next].copy(), clip.root_rot[idx_next].copy(), clip.joints[idx_next].copy()
    if clip.loop:
        t_prev[0] = -(t[-1] - t[-2])
        t_next[-1] = t[-1] + (t[1] - t[0])
        a = clip.sample(np.array([t_prev[0], t_next[-1]]))
        pp[0], rp[0], jp[0] = a[0][0], a[1][0], a[2][0]
        pn[-1], rn[-1], jn[-1] = a[0][1], a[1][1], a[2][1]
    dt = (t_next - t_prev)[:, None]
    root_lin = (pn - pp) / dt
    root_ang = rot.quat_to_expmap(rot.quat_multiply(rn, rot.quat_conjugate(rp))) / dt
    parts = []
    sk = clip.skeleton
    for j, s in zip(sk.joints, sk.q_slices.values()):
        if j.kind == SPHERICAL:
            parts.append(rot.quat_to_expmap(rot.quat_relative(jp[:, s], jn[:, s])) / dt)
        else:
            parts.append((jn[:, s] - jp[:, s]) / dt)
    return Velocities(root_lin, root_ang, np.concatenate(parts, axis=1))


@dataclasses.dataclass
class Kinematics:
    """World-frame link poses from forward kinematics.

    Attributes:
        links: link names, index = PyBullet link index.
        link_com: link centres of mass ``(n_frames, n_links, 3)`` ("link positions").
        joint_pos: link frame origins = joint positions ``(n_frames, n_links, 3)``.
        link_rot: link frame orientations ``x, y, z, w`` ``(n_frames, n_links, 4)``.
    """

    links: tuple[str, ...]
    link_com: np.ndarray
    joint_pos: np.ndarray
    link_rot: np.ndarray

    def index(self, name: str) -> int:
        return self.links.index(name)


def engine(hook: str = "forward_kinematics") -> Any:
    """The registered simulator class that provides ``hook``: the first by name whose class has it.

    Args:
        hook: a ``Simulator`` class hook: ``forward_kinematics``, ``kinematic_body`` or
            ``render_poses``.

    Raises:
        toolkit.errors.JtError: no registered simulator provides it.
    """
    from toolkit import plugins
    from toolkit.errors import JtError

    for name in plugins.names("sim"):
        try:
            cls = plugins.load("sim", name)
        except JtError:  # a broken plugin (jt plugins lists it): the next one may do
            continue
        if getattr(cls, hook, None) is not None:
            return cls
    raise JtError(f"no registered simulator provides {hook} (Simulator.{hook}); mocap kinematics "
                  f"need one (simulators: {', '.join(plugins.names('sim')) or 'none'})")


def forward_kinematics(skeleton: Skeleton, root_pos: np.ndarray, root_rot: np.ndarray,
                       joints: np.ndarray) -> Kinematics:
    """Link poses of each pose, by the simulator that provides ``forward_kinematics``.

    Args:
        skeleton: the character.
        root_pos: root (base) positions ``(n, 3)``.
        root_rot: root orientations ``x, y, z, w`` ``(n, 4)``.
        joints: poses in the quaternion layout ``(n, n_q)``.

    Returns:
        ``Kinematics`` with arrays ``(n, n_links, ...)``.
    """
    return engine("forward_kinematics").forward_kinematics(skeleton, root_pos, root_rot, joints)


def kinematic_body(skeleton: Skeleton) -> Any:
    """A kinematic copy of the skeleton's character (never stepped), by the simulator that provides
    ``kinematic_body``: ``masses`` ``(n_links + 1,)``, ``pose(q)``, ``lowest_point(q, link=None)``,
    ``links_and_com(q)`` and ``close()`` (``q`` in the ``toolkit.dynamics`` layout ``(n_q,)``)."""
    return engine("kinematic_body").kinematic_body(skeleton)
