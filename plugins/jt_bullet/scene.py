"""The PyBullet world the simulator runs in: a DIRECT client, y-up gravity, a ground plane.

jt's world is y-up as the DeepMimic data (gravity ``(0, -g, 0)``). PyBullet's
``plane_implicit.urdf`` has its normal along +z, so it is loaded turned by -90 degrees about x
(normal +y), exactly as pybullet's DeepMimic environment does; lateral friction 0.9 as there.
"""

from __future__ import annotations

import math
from typing import Any

Z_TO_Y = (-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))  #: quaternion x,y,z,w turning +z into +y


def connect(dt: float, gravity: float = 9.8, ground: bool = True, friction: float = 0.9,
            solver_iterations: int = 0) -> tuple[int, int]:
    """A new DIRECT client (a GUI one when ``toolkit.render.request_window`` asked for a window)
    with a fixed time step, y-up gravity and (optionally) a ground.

    Args:
        dt: simulation time step in seconds (``setTimeStep``).
        gravity: magnitude of gravity along -y, m/s^2 (0 switches it off).
        ground: load the ground plane (normal +y, through the origin).
        friction: lateral friction of the ground.
        solver_iterations: PyBullet's constraint solver iterations (0 keeps PyBullet's default).

    Returns:
        ``(client, ground_id)``; ``ground_id`` is -1 without a ground.
    """
    import pybullet as pb
    import pybullet_data

    from toolkit.render import window_requested

    client = _window() if window_requested() else pb.connect(pb.DIRECT)
    kw = {"physicsClientId": client}
    pb.setAdditionalSearchPath(pybullet_data.getDataPath(), **kw)
    pb.setGravity(0.0, -float(gravity), 0.0, **kw)
    pb.setTimeStep(float(dt), **kw)
    # contact pairs in a sorted order: without it the order depends on the pairs an earlier episode
    # made and removed (a jump into the bar), and the same state and action step differently in a
    # world with that history than in a fresh one, so a resumed training (fresh worlds) drifted
    # from the uninterrupted one in the 7th digit (issue 55; tests/plugins/jt_tasks/jumping)
    pb.setPhysicsEngineParameter(numSubSteps=1, deterministicOverlappingPairs=1, **kw)
    if solver_iterations > 0:
        pb.setPhysicsEngineParameter(numSolverIterations=int(solver_iterations), **kw)
    ground_id = -1
    if ground:
        ground_id = pb.loadURDF("plane_implicit.urdf", [0, 0, 0], list(Z_TO_Y),
                                useMaximalCoordinates=True, **kw)
        pb.changeDynamics(ground_id, -1, lateralFriction=float(friction), **kw)
    return client, ground_id


def _window() -> int:
    """A GUI client (``toolkit.render.request_window``: ``jt play --gui``), y up as jt's world;
    one ``JtError`` line when PyBullet cannot open one."""
    import pybullet as pb

    from toolkit.errors import JtError

    try:
        client = pb.connect(pb.GUI)
    except pb.error as e:  # e.g. a GUI already open in this process
        raise JtError(f"--gui: PyBullet cannot open a window ({e}); replay without --gui") from None
    if client < 0:
        raise JtError("--gui: PyBullet cannot open a window here (no OpenGL display?); replay without --gui")
    pb.configureDebugVisualizer(pb.COV_ENABLE_Y_AXIS_UP, 1, physicsClientId=client)
    pb.configureDebugVisualizer(pb.COV_ENABLE_GUI, 0, physicsClientId=client)
    return client


def set_friction(client: int, body: int, friction: float) -> None:
    """Lateral friction of every link of ``body`` (pybullet's DeepMimic humanoid: 0.9)."""
    import pybullet as pb

    kw = {"physicsClientId": client}
    for link in range(-1, pb.getNumJoints(body, **kw)):
        pb.changeDynamics(body, link, lateralFriction=float(friction), **kw)


def link_names(client: int, body: int) -> list[str]:
    """Child-link name of every joint of ``body`` (index = PyBullet link index)."""
    import pybullet as pb

    kw = {"physicsClientId": client}
    return [pb.getJointInfo(body, j, **kw)[12].decode() for j in range(pb.getNumJoints(body, **kw))]


def joint_names(client: int, body: int) -> list[str]:
    """Name of every joint of ``body`` (index = PyBullet joint index)."""
    import pybullet as pb

    kw = {"physicsClientId": client}
    return [pb.getJointInfo(body, j, **kw)[1].decode() for j in range(pb.getNumJoints(body, **kw))]


def find_link(client: int, body: int, name: str) -> int:
    """PyBullet link index of the link (or the joint whose child link) called ``name``.

    Raises:
        KeyError: no such link or joint; the message lists the link names.
    """
    links = link_names(client, body)
    if name in links:
        return links.index(name)
    joints = joint_names(client, body)
    if name in joints:
        return joints.index(name)
    if name in ("base", "root", "-1"):
        return -1
    raise KeyError(f"no link or joint {name!r}; links: {', '.join(links)}")


def contact_summary(client: int, body: int, n_links: int, other: int = -1) -> tuple[Any, int]:
    """Which links of ``body`` touch anything (or ``other`` if given), and how many points.

    Returns:
        ``(touching, n_points)``: ``touching`` is a bool array ``(n_links + 1,)`` indexed by
        PyBullet link index + 1 (entry 0 is the base).
    """
    import numpy as np
    import pybullet as pb

    kw = {"physicsClientId": client}
    pts = (pb.getContactPoints(bodyA=body, bodyB=other, **kw) if other >= 0
           else pb.getContactPoints(bodyA=body, **kw))
    touching = np.zeros(n_links + 1, dtype=bool)
    for p in pts:
        touching[p[3] + 1] = True
    return touching, len(pts)
