"""Typed configs of the ``bullet`` simulator (``cfg.sim``) and of a character (``cfg.character``).

``character`` is a plain config group (``conf/character/<name>.yaml``), not a plugin kind, so the
run-config check does not type it: ``CharacterConfig.from_node`` does, with the same one-line
errors. Gain overrides apply to the internal DoFs only; the root's gains come from
``SimConfig.root_servo``.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Optional

DEFAULT_CAMERA = {  # character: (distance m, yaw deg, pitch deg) for render(); ours
    "humanoid": (3.0, 0.0, -10.0), "laikago": (2.0, 0.0, -15.0), "atlas": (3.5, 0.0, -10.0),
    "snake36": (2.0, 0.0, -35.0), "snake72": (3.0, 0.0, -35.0), "snake195": (7.0, 0.0, -35.0),
}


@dataclasses.dataclass
class RootServo:
    """Hand-of-God root servo: SPD gains on the 6 root DoFs (001 §2.4.1); 0 = unactuated root."""

    kp: float = 0.0
    """Stiffness on root position (N/m) and orientation (N m/rad); 0: the root is free."""
    kd: float = 0.0
    """Damping on root linear (N s/m) and angular (N m s/rad) velocity."""


@dataclasses.dataclass
class SimConfig:
    """Parameters of the ``bullet`` simulator (the ``sim`` config group)."""

    name: str = "bullet"
    """Registry name."""
    sim_hz: float = 600.0
    """Simulation rate, Hz (000 §6.2, 002 §5: 600 Hz)."""
    control_hz: float = 30.0
    """Control rate, Hz; sim_hz / control_hz substeps per control step (002 §5: 30 Hz)."""
    gravity: float = 9.8
    """Gravity along -y, m/s^2 (0 switches it off)."""
    ground: bool = True
    """Load a ground plane (normal +y through the origin)."""
    friction: float = 0.9
    """Lateral friction of the ground and the character's links (pybullet's DeepMimic env)."""
    self_collision: Optional[bool] = None
    """Collisions between the character's links; None: the character's default (humanoid on)."""
    torque_limits: bool = True
    """Clip SPD torques to the character's limits after the solve (as DeepMimic / PyBullet)."""
    explode_speed: float = 80.0
    """A generalised velocity above this (m/s or rad/s) ends the episode as a failure (ours:
    the DeepMimic clips peak at 27 rad/s; PyBullet caps joint speeds at 100)."""
    explode_distance: float = 1000.0
    """A root farther than this from the origin (m) ends the episode as a failure."""
    contacts: bool = True
    """Summarise contacts (per-link flags, point count) in each step record."""
    solver_iterations: int = 0
    """PyBullet constraint solver iterations; 0 keeps PyBullet's default (50)."""
    root_servo: RootServo = dataclasses.field(default_factory=RootServo)
    """Hand-of-God root gains (tracking experiments, 001 §2.4.1); zero by default."""
    loop: str = "auto"
    """Where a control step's substeps run: compiled (one numba loop through PyBullet's C API,
    jt_bullet.fastloop; the same trajectory bit for bit, ~3x less time outside the physics),
    python (the reference loop), auto (compiled where it can: not with spd=bullet, a root servo
    or a PyBullet build without its symbol table)."""

    def check(self) -> None:
        """Rates, gravity and limits make sense (one ``JtError`` line)."""
        import math

        from toolkit.errors import JtError

        for key in ("sim_hz", "control_hz", "explode_speed", "explode_distance"):
            v = getattr(self, key)
            if not (math.isfinite(v) and v > 0):
                raise JtError(f"sim.{key}={v}: must be a finite number > 0")
        ratio = self.sim_hz / self.control_hz
        if abs(ratio - round(ratio)) > 1e-6 or round(ratio) < 1:
            raise JtError(f"sim.control_hz={self.control_hz:g}: sim_hz / control_hz must be a whole number "
                          f">= 1 (sim_hz={self.sim_hz:g}); e.g. 10, 15, 20, 30, 60")
        if not (math.isfinite(self.gravity) and self.gravity >= 0):
            raise JtError(f"sim.gravity={self.gravity}: must be >= 0 (m/s^2 along -y)")
        if not (math.isfinite(self.friction) and self.friction >= 0):
            raise JtError(f"sim.friction={self.friction}: must be >= 0")
        if self.solver_iterations < 0:
            raise JtError(f"sim.solver_iterations={self.solver_iterations}: must be >= 0 (0: PyBullet's default)")
        if self.loop not in ("auto", "compiled", "python"):
            raise JtError(f"sim.loop={self.loop!r}: choose auto, compiled or python")


@dataclasses.dataclass
class CharacterConfig:
    """A character to load and optional overrides of its gains (the ``character`` group)."""

    name: str = "humanoid"
    """One of humanoid, laikago, atlas, snake36, snake72, snake195 (jt_bullet.characters)."""
    kp: Optional[float] = None
    """Stiffness of every internal DoF; None keeps the character's own (see its YAML)."""
    kd: Optional[float] = None
    """Damping of every internal DoF; None keeps the character's own."""
    torque_limit: Optional[float] = None
    """Torque limit of every internal DoF (N m); None keeps the character's own."""
    joint_kp: dict[str, float] = dataclasses.field(default_factory=dict)
    """Per-joint stiffness by URDF joint name (applied after ``kp``)."""
    joint_kd: dict[str, float] = dataclasses.field(default_factory=dict)
    """Per-joint damping by URDF joint name."""
    joint_torque_limit: dict[str, float] = dataclasses.field(default_factory=dict)
    """Per-joint torque limit by URDF joint name."""
    camera_distance: Optional[float] = None
    """Render camera distance (m); None: a per-character default."""
    camera_yaw: Optional[float] = None
    """Render camera yaw (deg); None: a per-character default (0: seen from +z)."""
    camera_pitch: Optional[float] = None
    """Render camera pitch (deg, negative looks down); None: a per-character default."""

    @classmethod
    def from_node(cls, node: Any) -> "CharacterConfig":
        """Typed copy of a ``character`` node (dict, DictConfig, a name, or None: default)."""
        if isinstance(node, str):
            return cls(name=node)
        return typed(cls, node, "character")


def typed(cls: type, node: Any, group: str) -> Any:
    """``node`` (dict / DictConfig / dataclass / None) merged into dataclass ``cls`` as an object.

    Raises:
        JtError: unknown key or wrong type, in one line naming the group.
    """
    from omegaconf import OmegaConf

    from toolkit.errors import JtError

    if isinstance(node, cls):
        return node
    schema = OmegaConf.structured(cls)
    if node is None:
        return OmegaConf.to_object(schema)
    try:
        merged = OmegaConf.merge(schema, node)
    except Exception as e:  # noqa: BLE001 - OmegaConf raises several types
        msg = str(e).strip().splitlines()[0]
        valid = ", ".join(f.name for f in dataclasses.fields(cls))
        raise JtError(f"{group}: {msg} (valid keys: {valid})") from e
    return OmegaConf.to_object(merged)
