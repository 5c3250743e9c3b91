"""SPD backends (``jt.spd``): joint torques from Stable PD for one articulated body."""

from __future__ import annotations

import abc
from typing import TYPE_CHECKING, Any

from toolkit.interfaces.plugin import Plugin

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np


class SPDBackend(Plugin, abc.ABC):
    """Computes Stable PD torques (thesis ``001`` eq 2.4/2.6) at the current state.

    Generalised coordinates follow ``toolkit.dynamics`` (= PyBullet's ``getBase*`` and
    ``getJointStatesMultiDof``): for a floating base, ``q`` is root position (3), root orientation
    quaternion x,y,z,w (4) -- of PyBullet's base frame, i.e. the base link's inertial frame --
    then the joints in model order (spherical joints as x,y,z,w quaternions, revolute/prismatic
    as one scalar); ``qd`` has the root linear and angular velocity (6, world frame, as PyBullet
    reports them) then one entry per joint DoF (3 for a spherical joint, angular velocity in the
    child link's frame). Generalised forces use the ``qd`` layout (root: world force at the base
    frame origin, then world torque).

    Args:
        cfg: the ``spd`` config group, validated against ``Config``.
    """

    def __init__(self, cfg: Any = None) -> None:
        self.cfg = cfg

    @abc.abstractmethod
    def bind(self, body: Any) -> None:
        """Prepare for one articulated body (e.g. a ``toolkit.dynamics.Model``)."""

    @abc.abstractmethod
    def torques(
        self,
        q: "np.ndarray",
        qd: "np.ndarray",
        q_target: "np.ndarray",
        kp: "np.ndarray",
        kd: "np.ndarray",
        dt: float,
        qd_target: "np.ndarray | None" = None,
        tau_ext: "np.ndarray | None" = None,
    ) -> "np.ndarray":
        """SPD generalised forces ``(n_dof,)`` for targets at the next step.

        Args:
            q: generalised positions ``(n_q,)``.
            qd: generalised velocities ``(n_dof,)``.
            q_target: target positions ``(n_q,)`` (same layout as ``q``).
            kp: stiffness per DoF ``(n_dof,)`` (0 for unactuated DoFs).
            kd: damping per DoF ``(n_dof,)``.
            dt: time step in seconds.
            qd_target: target velocities ``(n_dof,)``, zero if ``None``.
            tau_ext: other known generalised forces ``(n_dof,)`` acting this step (e.g. gravity
                is already part of the bias term; this is for extra forces), zero if ``None``.
        """
