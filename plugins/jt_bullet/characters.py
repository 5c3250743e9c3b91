"""The thesis' character models, loaded into a PyBullet client, with PD gains and torque limits.

World convention: y-up, as the DeepMimic data (gravity ``(0, -9.8, 0)`` is the caller's
``setGravity``). Z-up models (Atlas) are rotated at load so that their up axis is +y.

Every loader disables PyBullet's default joint motors (so torques are the only actuation) and sets
link/joint damping to 0, so the simulated dynamics are exactly the rigid-body model that
``jt_bullet.model.model_from_bullet`` reads; joint limits from the URDF are kept. Link inertias:
the humanoid is loaded as pybullet's DeepMimic environment does (PyBullet derives the inertia
tensors from the collision shapes, masses from the URDF); the others with
``URDF_USE_INERTIA_FROM_FILE`` (the URDF's own tensors; for the snakes both are the same).

Gains (``kp``, ``kd`` per DoF, ``(n_dof,)``, 0 on the 6 root DoFs of a floating base) and torque
limits (``(n_dof,)``, 0 on the root) come from:

* ``humanoid``: the papers / DeepMimic (``000`` §6.1, ``001`` §2.4, ``002``): kp chest 1000,
  neck 100, hip 500, knee 500, ankle 400, shoulder 400, elbow 300; kd = kp / 10; torque limits
  200 / 50 / 200 / 150 / 90 / 100 / 60 N m.
* ``laikago``: ours (no paper value): kp 400, kd 40 on every joint; limit = the URDF effort
  (100 N m).
* ``atlas``: ours: kp = 10 x URDF effort (N m / rad), kd = kp / 10, limit = URDF effort.
* ``snake36/72/195``: ours: kp 10, kd 1, limit 10 N m on every spherical DoF.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Callable

import numpy as np

from jt_bullet import urdfgen

Y_UP_FROM_Z_UP = (-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))  #: quaternion turning +z into +y

HUMANOID_GAINS = {  # joint: (kp, torque limit); kd = kp / 10      # 000 §6.1, 001 §2.4
    "chest": (1000.0, 200.0), "neck": (100.0, 50.0),
    "right_hip": (500.0, 200.0), "left_hip": (500.0, 200.0),
    "right_knee": (500.0, 150.0), "left_knee": (500.0, 150.0),
    "right_ankle": (400.0, 90.0), "left_ankle": (400.0, 90.0),
    "right_shoulder": (400.0, 100.0), "left_shoulder": (400.0, 100.0),
    "right_elbow": (300.0, 60.0), "left_elbow": (300.0, 60.0),
}
SNAKE_SEGMENTS = {"snake36": 10, "snake72": 22, "snake195": 63}  #: n = 6 + 3k (001 Table 2.1)


@dataclasses.dataclass
class Character:
    """A loaded character: PyBullet handles, DoF layout, gains and limits.

    Attributes:
        name: character name (``humanoid``, ``laikago``, ``atlas``, ``snake36`` ...).
        body_id: PyBullet body unique id.
        client: PyBullet physics client id.
        kp: stiffness per DoF ``(n_dof,)``.
        kd: damping per DoF ``(n_dof,)``.
        torque_limit: symmetric torque limit per DoF ``(n_dof,)`` (0 on an unactuated root).
        joint_indices: PyBullet indices of the movable joints, in DoF order.
        joint_dofs: DoFs of each of those joints (3 spherical, 1 revolute/prismatic).
        fixed_base: whether the base is fixed to the world.
        n_q: length of the generalised position vector.
        n_dof: number of DoFs (6 root DoFs included for a floating base).
        q_init: the pose the character was loaded in ``(n_q,)`` (``toolkit.dynamics`` layout).
        urdf: path of the URDF loaded.
        gains_source: where ``kp``/``kd``/``torque_limit`` come from.
    """

    name: str
    body_id: int
    client: int
    kp: np.ndarray
    kd: np.ndarray
    torque_limit: np.ndarray
    joint_indices: list[int]
    joint_dofs: list[int]
    fixed_base: bool
    n_q: int
    n_dof: int
    q_init: np.ndarray
    urdf: str
    gains_source: str

    def model(self) -> Any:
        """The ``toolkit.dynamics.Model`` of this body."""
        from jt_bullet.model import model_from_bullet

        return model_from_bullet(self.client, self.body_id, name=self.name,
                                 floating=not self.fixed_base)

    def body_io(self) -> Any:
        """A ``jt_bullet.body.BulletBody`` reading and driving this body through its model."""
        from jt_bullet.body import BulletBody

        return BulletBody(self.client, self.body_id, self.model())


def _client_id(client: Any) -> int:
    return int(getattr(client, "_client", client))


def _load(name: str, client: Any, urdf: str, pos: Any, orn: Any, fixed_base: bool, flags: int,
          gains: Callable[[Any, int, int, dict], tuple[float, float, float]], source: str,
          scaling: float = 1.0) -> Character:
    """Load a URDF, switch off default motors and damping, and assemble the ``Character``."""
    import pybullet as pb
    import pybullet_data

    cid = _client_id(client)
    kw = {"physicsClientId": cid}
    pb.setAdditionalSearchPath(pybullet_data.getDataPath(), **kw)
    from toolkit.quiet import native_stderr_silenced

    with native_stderr_silenced():  # the DeepMimic URDF warns once per spherical joint
        body = pb.loadURDF(urdf, list(pos), list(orn), useFixedBase=fixed_base, flags=flags,
                           globalScaling=scaling, **kw)
    pb.changeDynamics(body, -1, linearDamping=0.0, angularDamping=0.0, **kw)
    joints, dofs, kp, kd, lim = [], [], [], [], []
    base_dofs = 0 if fixed_base else 6
    kp += [0.0] * base_dofs
    kd += [0.0] * base_dofs
    lim += [0.0] * base_dofs
    for j in range(pb.getNumJoints(body, **kw)):
        info = pb.getJointInfo(body, j, **kw)
        pb.changeDynamics(body, j, linearDamping=0.0, angularDamping=0.0, jointDamping=0.0, **kw)
        jtype = info[2]
        if jtype == pb.JOINT_SPHERICAL:
            pb.setJointMotorControlMultiDof(body, j, pb.POSITION_CONTROL,
                                            targetPosition=[0, 0, 0, 1], targetVelocity=[0, 0, 0],
                                            positionGain=0, velocityGain=1, force=[0, 0, 0], **kw)
            n = 3
        elif jtype in (pb.JOINT_REVOLUTE, pb.JOINT_PRISMATIC):
            pb.setJointMotorControl2(body, j, pb.VELOCITY_CONTROL, targetVelocity=0, force=0, **kw)
            n = 1
        else:
            continue
        p_gain, d_gain, t_lim = gains(pb, body, j, {"info": info, "kw": kw})
        joints.append(j)
        dofs.append(n)
        kp += [p_gain] * n
        kd += [d_gain] * n
        lim += [t_lim] * n
    pos_c, orn_c = pb.getBasePositionAndOrientation(body, **kw)
    q = [] if fixed_base else list(pos_c) + list(orn_c)
    for n in dofs:  # PyBullet loads every joint at zero (not read back: see jt_bullet.body's limits)
        q += [0.0, 0.0, 0.0, 1.0] if n == 3 else [0.0]
    return Character(name=name, body_id=body, client=cid, kp=np.array(kp), kd=np.array(kd),
                     torque_limit=np.array(lim), joint_indices=joints, joint_dofs=dofs,
                     fixed_base=fixed_base, n_q=len(q), n_dof=len(kp), q_init=np.array(q),
                     urdf=urdf, gains_source=source)


def _self_collision_flags(pb: Any, self_collision: bool, inertia_from_file: bool = True) -> int:
    flags = pb.URDF_MAINTAIN_LINK_ORDER
    if inertia_from_file:
        flags |= pb.URDF_USE_INERTIA_FROM_FILE
    if self_collision:
        flags |= pb.URDF_USE_SELF_COLLISION | pb.URDF_USE_SELF_COLLISION_EXCLUDE_ALL_PARENTS
    return flags


def humanoid(client: Any, base_position: Any = (0.0, 0.889540259, 0.0),
             base_orientation: Any = (0.0, 0.0, 0.0, 1.0), fixed_base: bool = False,
             self_collision: bool = True) -> Character:
    """DeepMimic humanoid (``humanoid/humanoid.urdf`` x 0.25): 34 DoF, 12 internal joints.

    Spherical chest, neck, hips, ankles, shoulders; revolute knees and elbows. The default base
    position and flags are those of pybullet's DeepMimic environment (inertias from the shapes).
    """
    import pybullet as pb

    def gains(pb_: Any, body: int, j: int, ctx: dict) -> tuple[float, float, float]:
        kp, lim = HUMANOID_GAINS[ctx["info"][1].decode()]
        return kp, kp / 10.0, lim

    return _load("humanoid", client, "humanoid/humanoid.urdf", base_position, base_orientation,
                 fixed_base, _self_collision_flags(pb, self_collision, inertia_from_file=False),
                 gains, "000 §6.1 / 001 §2.4 (DeepMimic humanoid)", scaling=0.25)


def laikago(client: Any, base_position: Any = (0.0, 0.48, 0.0),
            base_orientation: Any = (0.0, 0.0, 0.0, 1.0), fixed_base: bool = False,
            self_collision: bool = False) -> Character:
    """Laikago quadruped (``laikago/laikago_toes.urdf``, y-up): 18 DoF, 12 revolute joints."""
    import pybullet as pb

    def gains(pb_: Any, body: int, j: int, ctx: dict) -> tuple[float, float, float]:
        return 400.0, 40.0, float(ctx["info"][10])

    return _load("laikago", client, "laikago/laikago_toes.urdf", base_position, base_orientation,
                 fixed_base, _self_collision_flags(pb, self_collision), gains,
                 "ours: kp 400, kd 40; limit = URDF effort")


def atlas(client: Any, base_position: Any = (0.0, 0.95, 0.0),
          base_orientation: Any = Y_UP_FROM_Z_UP, fixed_base: bool = False,
          self_collision: bool = False) -> Character:
    """Boston Dynamics Atlas v4: 36 DoF, 30 revolute joints (z-up model turned y-up).

    Uses ``pybullet_data``'s ``atlas/atlas_v4_with_multisense.urdf`` when installed, otherwise
    the mesh-free copy from ``jt_bullet.urdfgen.atlas_urdf`` (same kinematics and inertias).
    """
    import os

    import pybullet as pb
    import pybullet_data

    path = os.path.join(pybullet_data.getDataPath(), "atlas", "atlas_v4_with_multisense.urdf")
    urdf = path if os.path.exists(path) else urdfgen.write_cached("atlas", urdfgen.atlas_urdf())

    def gains(pb_: Any, body: int, j: int, ctx: dict) -> tuple[float, float, float]:
        effort = float(ctx["info"][10])
        return 10.0 * effort, effort, effort

    return _load("atlas", client, urdf, base_position, base_orientation, fixed_base,
                 _self_collision_flags(pb, self_collision), gains,
                 "ours: kp = 10 x URDF effort, kd = kp / 10; limit = URDF effort")


def snake(client: Any, name: str = "snake36", base_position: Any = (0.0, 0.05, 0.0),
          base_orientation: Any = (0.0, 0.0, 0.0, 1.0), fixed_base: bool = False,
          self_collision: bool = False) -> Character:
    """Generated snake: floating root segment + k spherical segments, ``n = 6 + 3k`` = d."""
    import pybullet as pb

    k = SNAKE_SEGMENTS[name]
    urdf = urdfgen.write_cached(name, urdfgen.snake_urdf(k))

    def gains(pb_: Any, body: int, j: int, ctx: dict) -> tuple[float, float, float]:
        return 10.0, 1.0, 10.0

    return _load(name, client, urdf, base_position, base_orientation, fixed_base,
                 _self_collision_flags(pb, self_collision), gains, "ours: kp 10, kd 1, limit 10")


def snake36(client: Any, **kw: Any) -> Character:
    """36-DoF snake (10 spherical segments), thesis Snake1."""
    return snake(client, "snake36", **kw)


def snake72(client: Any, **kw: Any) -> Character:
    """72-DoF snake (22 spherical segments), thesis Snake2."""
    return snake(client, "snake72", **kw)


def snake195(client: Any, **kw: Any) -> Character:
    """195-DoF snake (63 spherical segments), thesis Snake3."""
    return snake(client, "snake195", **kw)


LOADERS: dict[str, Callable[..., Character]] = {
    "humanoid": humanoid, "laikago": laikago, "atlas": atlas,
    "snake36": snake36, "snake72": snake72, "snake195": snake195,
}


def load(name: str, client: Any, **kw: Any) -> Character:
    """Load a character by name (one of ``LOADERS``)."""
    try:
        loader = LOADERS[name]
    except KeyError:
        raise ValueError(f"unknown character {name!r}; known: {sorted(LOADERS)}") from None
    return loader(client, **kw)


def load_configured(name: Any, client: Any, **kw: Any) -> "Character":
    """Load a character into ``client`` with a ``CharacterConfig``'s gain overrides applied.

    For tools (``jt bench spd``) that need the built-in characters without a simulator.

    Args:
        name: a character name, or a ``character`` config node / ``CharacterConfig``.
        client: PyBullet client id.
        **kw: passed to the loader (``base_position``, ``self_collision`` ...).

    Returns:
        A ``jt_bullet.characters.Character`` (``kp``, ``kd``, ``torque_limit`` overridden).

    Raises:
        UnknownName: ``joint_kp`` / ``joint_kd`` / ``joint_torque_limit`` names a joint the
        character has not (a one-line ``JtError``, also a ``KeyError``; it lists the
        movable joints).
    """
    from jt_bullet import scene
    from jt_bullet.config import CharacterConfig
    from jt_bullet.queries import UnknownName

    cc = CharacterConfig.from_node(name)
    ch = load(cc.name, client, **kw)
    if cc.kp is None and cc.kd is None and cc.torque_limit is None and not (
            cc.joint_kp or cc.joint_kd or cc.joint_torque_limit):
        return ch
    base = 0 if ch.fixed_base else 6
    for arr, value in ((ch.kp, cc.kp), (ch.kd, cc.kd), (ch.torque_limit, cc.torque_limit)):
        if value is not None:
            arr[base:] = float(value)
    names = scene.joint_names(ch.client, ch.body_id)
    slices, k = {}, base
    for j, n in zip(ch.joint_indices, ch.joint_dofs):
        slices[names[j]] = slice(k, k + n)
        k += n
    for arr, table in ((ch.kp, cc.joint_kp), (ch.kd, cc.joint_kd), (ch.torque_limit, cc.joint_torque_limit)):
        for joint, value in table.items():
            if joint not in slices:
                raise UnknownName(f"character {cc.name!r} has no movable joint {joint!r}; "
                                  f"joints: {', '.join(slices)}")
            arr[slices[joint]] = float(value)
    ch.gains_source += " (overridden by the character config)"
    return ch
