"""A torque-controlled URDF of its own on a ground plane: the ``bullet`` simulator's planar world.

``BulletSimulator`` drives one of jt's characters with SPD in a y-up world; some tasks simulate a
model of their own instead, with their own controller — ``task=standing_jump``'s planar 17-link
jumper (``004``), whose URDF puts the root on three joints (x, z, pitch) of a fixed base. This
module is all the PyBullet such a task needs: one DIRECT client per world (nothing shared between
worlds, so equal inputs give equal results), z up, gravity along z, a ground plane, the model
loaded with the inertias of its file, no restitution, no damping, the default joint motors off.
The task reads joint states in one batched call, writes torques (``TORQUE_CONTROL``) and steps;
it may change gravity (a supernatural assist) and read its contacts with the ground.

Get one through the registry, never by importing this plugin::

    world = plugins.load("sim", "bullet").planar_world(urdf, sim_hz=600.0, friction=1.0)
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

import numpy as np

GROUND_HALF_EXTENTS = (20.0, 2.0, 0.005)  #: the ground's visual strip, m (collision: a plane)
GROUND_RGBA = (0.85, 0.85, 0.8, 1.0)


class PlanarWorld:
    """One fixed-base URDF on a ground plane, torque-controlled, in its own PyBullet client.

    Joint arrays are in PyBullet joint order (index ``i`` = joint ``i`` of the file).

    Attributes:
        joint_names: name of every joint ``(n,)``.
        link_names: name of every joint's child link ``(n,)``.
        n_joints: number of joints ``n``.
        client: the PyBullet client id (for tests that check against PyBullet itself).
        robot: the model's body id.
        ground: the ground's body id.

    Args:
        urdf_path: the model file (z up).
        sim_hz: simulation rate, Hz (time step ``1 / sim_hz``).
        friction: lateral friction of the ground and of every link (restitution 0).
        gravity: vertical gravity, m/s² (along z).
    """

    def __init__(self, urdf_path: str | Path, sim_hz: float, friction: float,
                 gravity: float = -9.8) -> None:
        import pybullet as p

        self._p = p
        cid = p.connect(p.DIRECT)
        self.client = cid
        self._kw = {"physicsClientId": cid}
        kw = self._kw
        p.setGravity(0.0, 0.0, gravity, **kw)
        p.setTimeStep(1.0 / sim_hz, **kw)
        shape = p.createCollisionShape(p.GEOM_PLANE, **kw)
        visual = p.createVisualShape(p.GEOM_BOX, halfExtents=list(GROUND_HALF_EXTENTS),
                                     rgbaColor=list(GROUND_RGBA),
                                     visualFramePosition=[0, 0, -GROUND_HALF_EXTENTS[2]], **kw)
        self.ground = p.createMultiBody(0, shape, visual, **kw)
        self.robot = robot = p.loadURDF(str(urdf_path), useFixedBase=True,
                                        flags=p.URDF_USE_INERTIA_FROM_FILE, **kw)
        n = p.getNumJoints(robot, **kw)
        infos = [p.getJointInfo(robot, i, **kw) for i in range(n)]
        self.n_joints = n
        self.joint_names = [info[1].decode() for info in infos]
        self.link_names = [info[12].decode() for info in infos]
        self._all = list(range(n))
        p.changeDynamics(self.ground, -1, lateralFriction=friction, restitution=0.0, **kw)
        for i in range(-1, n):
            p.changeDynamics(robot, i, lateralFriction=friction, restitution=0.0, linearDamping=0.0,
                             angularDamping=0.0, jointDamping=0.0, **kw)
        p.setJointMotorControlArray(robot, self._all, p.VELOCITY_CONTROL, forces=[0.0] * n, **kw)

    # ------------------------------------------------------------------ state
    def reset_joint(self, joint: int, position: float, velocity: float = 0.0) -> None:
        """Set one joint's position and velocity (no dynamics; forward kinematics follows)."""
        self._p.resetJointState(self.robot, int(joint), position, velocity, **self._kw)

    def reset_joints(self, q: Sequence[float], qd: Sequence[float] | None = None) -> None:
        """Set the positions ``q`` ``(n,)`` (and velocities ``qd`` ``(n,)``, else zero) of joints
        ``0 .. len(q) - 1``."""
        for i, v in enumerate(q):
            self.reset_joint(i, v, 0.0 if qd is None else qd[i])

    def joint_states(self) -> tuple[list[float], list[float]]:
        """Positions ``(n,)`` and velocities ``(n,)`` of every joint, in one batched read."""
        js = self._p.getJointStates(self.robot, self._all, **self._kw)
        return [s[0] for s in js], [s[1] for s in js]

    def ground_contacts(self) -> list[tuple[int, float]]:
        """``(link index, normal force (N))`` of every contact point of the model with the ground,
        in PyBullet's order (a link may appear several times)."""
        pts = self._p.getContactPoints(self.robot, self.ground, **self._kw)
        return [(c[3], c[9]) for c in pts]

    def model(self) -> Any:
        """The model's ``toolkit.dynamics.Model`` (fixed base; q layout = joint order; gravity
        read from the world now)."""
        from jt_bullet.model import model_from_bullet

        return model_from_bullet(self.client, self.robot)

    # ------------------------------------------------------------------ dynamics
    def set_gravity(self, g: float) -> None:
        """Vertical gravity ``g`` (m/s², along z) from the next step on."""
        self._p.setGravity(0.0, 0.0, g, **self._kw)

    def apply_torques(self, tau: Sequence[float]) -> None:
        """Torques (forces on prismatic joints) ``(n,)`` for the next step, every joint."""
        self._p.setJointMotorControlArray(self.robot, self._all, self._p.TORQUE_CONTROL,
                                          forces=tau, **self._kw)

    def step(self) -> None:
        """One simulation step of ``1 / sim_hz`` s."""
        self._p.stepSimulation(**self._kw)

    # ------------------------------------------------------------------ output
    def render(self, width: int, height: int, eye: Sequence[float], target: Sequence[float],
               up: Sequence[float] = (0, 0, 1), fov: float = 45.0, near: float = 0.1,
               far: float = 20.0, light_direction: Sequence[float] = (-1, -2, 3)) -> np.ndarray:
        """An RGB frame by TinyRenderer (headless, no shadows).

        Args:
            width: image width, px.
            height: image height, px.
            eye: camera position ``(3,)``, m.
            target: the point looked at ``(3,)``, m.
            up: the camera's up direction ``(3,)``.
            fov: vertical field of view, degrees.
            near: near clipping distance, m.
            far: far clipping distance, m.
            light_direction: direction towards the light ``(3,)``.

        Returns:
            ``(height, width, 3)`` uint8.
        """
        p, kw = self._p, self._kw
        proj = p.computeProjectionMatrixFOV(fov=fov, aspect=width / height, nearVal=near,
                                            farVal=far, **kw)
        view = p.computeViewMatrix(list(eye), list(target), list(up), **kw)
        img = p.getCameraImage(width, height, view, proj, renderer=p.ER_TINY_RENDERER,
                               lightDirection=list(light_direction), shadow=0, **kw)[2]
        return np.asarray(img, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]

    def close(self) -> None:
        """Disconnect the client (idempotent). A world is never closed behind its caller's back:
        one handed out as raw ids (``client``, ``robot``) stays open until closed."""
        if self.client is not None:
            try:
                self._p.disconnect(**self._kw)
            except Exception:  # noqa: BLE001 - already disconnected
                pass
            self.client = None

    def __enter__(self) -> "PlanarWorld":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
