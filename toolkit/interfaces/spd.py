"""SPD backends (``jt.spd``): joint torques from Stable PD for one articulated body."""

from __future__ import annotations

import abc
from typing import TYPE_CHECKING, Any, ClassVar

from toolkit.interfaces.plugin import GroupPlugin

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np


class SPDBackend(GroupPlugin, abc.ABC):
    """Computes Stable PD torques (thesis ``001`` eq 2.4/2.6) at the current state.

    Generalised coordinates follow ``toolkit.dynamics`` (= PyBullet's ``getBase*`` and
    ``getJointStatesMultiDof``): for a floating base, ``q`` is root position (3), root orientation
    quaternion x,y,z,w (4) -- of PyBullet's base frame, i.e. the base link's inertial frame --
    then the joints in model order (spherical joints as x,y,z,w quaternions, revolute/prismatic
    as one scalar); ``qd`` has the root linear and angular velocity (6, world frame, as PyBullet
    reports them) then one entry per joint DoF (3 for a spherical joint, angular velocity in the
    child link's frame). Generalised forces use the ``qd`` layout (root: world force at the base
    frame origin, then world torque).

    Required: ``bind`` and ``torques``. Optional, with defaults: ``steps_itself`` (False),
    ``solve`` (= ``torques``), ``control`` (read, ``torques``, clip, apply), and ``apply`` (only a
    backend with ``steps_itself`` has one).

    Attributes:
        steps_itself: False (default): ``torques`` returns the SPD torques, which the caller clips
            and applies before stepping the engine. True: the backend acts inside the engine's own
            step (PyBullet's STABLE_PD: ``spd=bullet``): it is bound to the engine's body (the
            simulator's body I/O object, see ``control``) instead of a ``Model``, the simulator calls
            ``apply`` before every substep, and ``torques`` may raise ``NotImplementedError``.

    Args:
        cfg: the ``spd`` config group, validated against ``Config``.
    """

    what: ClassVar[str] = "spd={name}"

    steps_itself: ClassVar[bool] = False

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)

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

    def solve(self, q: "np.ndarray", qd: "np.ndarray", q_target: "np.ndarray", kp: "np.ndarray",
              kd: "np.ndarray", dt: float, qd_target: "np.ndarray | None" = None) -> "np.ndarray":
        """The simulator's per-substep path: ``torques`` for contiguous float64 arrays; a backend
        may override it with a leaner one (no conversions). The default calls ``torques``."""
        return self.torques(q, qd, q_target, kp, kd, dt, qd_target)

    def control(self, io: Any, q_target: "np.ndarray", kp: "np.ndarray", kd: "np.ndarray", dt: float,
                torque_limit: "np.ndarray", qd_target: "np.ndarray | None" = None) -> Any:
        """One substep's control of a body through the simulator's body I/O object ``io``
        (``io.read() -> (q, qd)``, ``io.write_torques(tau)``; ``sim=bullet``'s ``BulletBody``):
        read the state, compute the torques, clip them to ``±torque_limit`` and write them; the
        caller then steps the engine. Returns the applied torques ``(n_dof,)``."""
        import numpy as np

        q, qd = io.read()
        tau = np.clip(self.torques(q, qd, q_target, kp, kd, dt, qd_target), -torque_limit, torque_limit)
        io.write_torques(tau)
        return tau

    def apply(self, q_target: "np.ndarray", kp: "np.ndarray", kd: "np.ndarray",
              torque_limit: "np.ndarray", qd_target: "np.ndarray | None" = None) -> None:
        """Arm the engine's own controller for the next step (backends with ``steps_itself``
        only; the default says the backend has none)."""
        raise NotImplementedError(f"{type(self).__name__} computes torques (steps_itself is False): "
                                  "call torques(...) and apply them")
