"""``spd=bullet``: PyBullet's own C++ Stable PD (``STABLE_PD_CONTROL``), as a reference.

It acts inside ``stepSimulation`` and never hands torques back, so it has a different protocol:
``steps_itself = True`` and ``apply(...)`` arms it for the next ``stepSimulation``. A simulator
does, per substep::

    if backend.steps_itself:
        backend.apply(q_target, kp, kd, torque_limit)   # PyBullet computes + clips in the step
    else:
        backend.control(io, q_target, kp, kd, dt, torque_limit)
    p.stepSimulation()

PyBullet solves SPD with DeepMimic's ``cRBDModel`` built from the multibody, whose link inertias
come from the collision shapes (box/capsule/sphere) rather than the URDF ``<inertial>`` tensors:
it matches exact SPD (``maba``/``df``) to ~1e-10 where the two agree (our snakes), and differs
where they do not (one-step accelerations on random states: humanoid ~3 %, atlas and laikago with
their URDF inertias > 100 %; see docs/maba.md). It takes
one gain per joint, has no root servo and no target velocity per DoF beyond what PyBullet passes,
and cannot drive bodies with more than 128 position coordinates (the 195-DoF snake).
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

from toolkit.interfaces import SPDBackend


class BulletBackend(SPDBackend):
    """PyBullet's built-in C++ Stable PD (STABLE_PD_CONTROL), applied inside stepSimulation."""

    #: True: arms PyBullet's controller; the torques are computed in ``stepSimulation``
    steps_itself: ClassVar[bool] = True

    @dataclasses.dataclass
    class Config:
        name: str = "bullet"
        """Registry name."""

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        self.io: Any = None

    def bind(self, body: Any) -> None:
        """Attach to a PyBullet body: ``sim=bullet``'s ``BulletBody`` (what has ``stable_pd``) or a
        Character (what has ``body_io``); the simulator plugin owns both, so none is imported."""
        if hasattr(body, "stable_pd"):
            self.io = body
            return
        if hasattr(body, "body_io"):
            self.io = body.body_io()
            return
        raise TypeError("bullet SPD needs a BulletBody or a Character (a PyBullet body), "
                        f"got {type(body).__name__}")

    def apply(self, q_target: Any, kp: Any, kd: Any, torque_limit: Any,
              qd_target: Any = None) -> None:
        """Arm STABLE_PD_CONTROL for the next ``stepSimulation`` (root unactuated)."""
        if self.io is None:
            raise RuntimeError("SPD backend 'bullet': call bind(body) first")
        self.io.stable_pd(q_target, kp, kd, torque_limit, qd_target)

    def control(self, io: Any, q_target: Any, kp: Any, kd: Any, dt: float, torque_limit: Any,
                qd_target: Any = None) -> None:
        """Same signature as the other backends' ``control``; ``dt`` is PyBullet's time step."""
        if self.io is None or self.io is not io:
            self.bind(io)
        self.apply(q_target, kp, kd, torque_limit, qd_target)

    def torques(self, q: Any, qd: Any, q_target: Any, kp: Any, kd: Any, dt: float,
                qd_target: Any = None, tau_ext: Any = None) -> Any:
        raise NotImplementedError(
            f"spd={self.params.name} computes its torques inside PyBullet's stepSimulation "
            "and never returns them; call apply(q_target, kp, kd, torque_limit) before each stepSimulation "
            "(steps_itself is True)")
