"""``spd=servo``: PyBullet's constraint motors (``POSITION_CONTROL``), solved with the contacts.

Stable PD (every other backend) predicts the next step's acceleration from the body's mass matrix
alone, so it knows nothing of contacts: a joint whose child is light and held by the ground — an
ankle with its sole planted — gets a torque scaled by ``I_child / (I_child + kd·dt)`` of what its
gain asks (jt's humanoid: ~5 N·m instead of ~130 N·m for a 0.33 rad ankle error; docs/getup.md
"Why a held standing pose falls"). A pose held that way sags and falls within ~1.5 s.

A constraint motor is solved *inside* the engine's constraint solver together with the contacts,
as the PD servos of a game-style engine are (003 used Vortex's): each joint is a velocity
constraint driving it by ``position_gain`` of its position error per step and ``velocity_gain``
of its velocity error, its force bounded by the character's torque limits. It is stiff up to those
limits — the character's ``kp``/``kd`` are not used — and PyBullet reports no torques (the step
record's ``tau`` is NaN, as for ``spd=bullet``). Like ``spd=bullet`` it ``steps_itself``, has no
root servo and cannot drive bodies with more than 128 position coordinates.
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

from jt_spd.bullet import BulletBackend


class ServoBackend(BulletBackend):
    """PyBullet's constraint motors (POSITION_CONTROL), bounded by the torque limits."""

    #: how ``jt_bullet.compiled`` steps it: no kernel, the motors armed once per control step
    method: ClassVar[str] = "servo"

    @dataclasses.dataclass
    class Config:
        name: str = "servo"
        """Registry name."""
        position_gain: float = 0.3
        """Share of the position error the motor's velocity target removes per physics step
        (PyBullet's ``positionGain``). On the fixed-base humanoid at 600 Hz, a 0.3 rad step of every
        spherical joint is 66 % done after 40 steps and settled (0.2 %) after 120 with 0.3; 0.1 is
        slower (11 % left at 120), 1.0 overshoots and rings."""
        velocity_gain: float = 1.0
        """Weight of the velocity error in the motor's velocity target (PyBullet's
        ``velocityGain``; with zero target velocities it changed nothing measured)."""

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        from toolkit.errors import JtError

        c = self.params
        for key in ("position_gain", "velocity_gain"):
            v = float(getattr(c, key))
            if not (0.0 < v <= 1.0):
                raise JtError(f"spd.{key}={v:g}: must be in (0, 1] (a share of the error per step)")
        self._armed: tuple | None = None  # (io, q_target, torque_limit, qd_target) last armed

    @classmethod
    def check_run(cls, cfg: Any) -> None:
        """The gains, checked at composition (before a run opens): one line for a bad one."""
        cls(cfg.get("spd") if hasattr(cfg, "get") else None)

    def apply(self, q_target: Any, kp: Any, kd: Any, torque_limit: Any,
              qd_target: Any = None) -> None:
        """Arm the motors towards ``q_target`` for the next ``stepSimulation`` (``kp``, ``kd`` unused)."""
        if self.io is None:
            raise RuntimeError("SPD backend 'servo': call bind(body) first")
        import numpy as np

        armed = self._armed
        if (armed is not None and armed[0] is self.io and np.array_equal(armed[1], q_target)
                and np.array_equal(armed[2], torque_limit)
                and (armed[3] is None) == (qd_target is None)
                and (qd_target is None or np.array_equal(armed[3], qd_target))):
            return  # the motors keep their targets through later steps: arm once per target
        self._armed = (self.io, np.array(q_target, dtype=float), np.array(torque_limit, dtype=float),
                       None if qd_target is None else np.array(qd_target, dtype=float))
        self.io.servo(q_target, torque_limit, qd_target, float(self.params.position_gain),
                      float(self.params.velocity_gain))
