"""Headless rendering with PyBullet's TinyRenderer (no display): a frame of the simulator's world
(``BulletSimulator.render``) and still poses of a skeleton (``BulletSimulator.render_poses``, the
pictures of decoded poses the priors save). Frames are RGB arrays ``(height, width, 3)`` uint8.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from toolkit.motion.skeletons import Skeleton
from toolkit.render import Camera


def render_frame(client: int, target: Sequence[float], width: int = 320, height: int = 240,
                 camera: Camera | None = None, body: int | None = None) -> Any:
    """One RGB frame ``(height, width, 3)`` uint8 from TinyRenderer, looking at ``target``; with
    ``body``, ``(frame, mask)``: the pixels that show that body, ``(height, width)`` bool."""
    import pybullet as p

    from toolkit.render import window_requested

    cam = camera or Camera()
    if window_requested():  # jt play --gui: the window's camera follows as the frames' does
        p.resetDebugVisualizerCamera(cam.distance, cam.yaw, cam.pitch, list(map(float, target)),
                                     physicsClientId=client)
    view = p.computeViewMatrixFromYawPitchRoll(
        cameraTargetPosition=list(map(float, target)), distance=cam.distance, yaw=cam.yaw,
        pitch=cam.pitch, roll=0.0, upAxisIndex=cam.up_axis, physicsClientId=client)
    proj = p.computeProjectionMatrixFOV(fov=cam.fov, aspect=width / height, nearVal=0.05, farVal=50.0,
                                        physicsClientId=client)
    _, _, rgba, _, seg = p.getCameraImage(width, height, view, proj, renderer=p.ER_TINY_RENDERER,
                                          physicsClientId=client)
    rgb = np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3].copy()
    if body is None:
        return rgb
    ids = np.asarray(seg, dtype=np.int64).reshape(height, width)
    return rgb, (ids >= 0) & ((ids & ((1 << 24) - 1)) == int(body))


def render_poses(
    skeleton: Skeleton,
    dofs: np.ndarray,
    width: int = 200,
    height: int = 240,
    distance: float = 2.0,
    yaw: float = 0.0,
    pitch: float = -10.0,
) -> list[np.ndarray]:
    """One RGB frame ``(height, width, 3)`` uint8 per pose.

    Args:
        skeleton: the character.
        dofs: poses in the dof layout ``(n, n_dof)`` (exp maps, angles); the root is placed at
            the origin, upright, facing +x.
        width: frame width in pixels.
        height: frame height in pixels.
        distance: camera distance from the root (m).
        yaw: camera yaw (degrees; 0 looks from the +z side).
        pitch: camera pitch (degrees; negative looks down).
    """
    import pybullet as pb

    from jt_bullet.kinematics import bullet_character

    dofs = np.atleast_2d(np.asarray(dofs, dtype=np.float64))
    joints = skeleton.dofs_to_joints(dofs)
    indices = [j.bullet_index for j in skeleton.joints]
    slices = list(skeleton.q_slices.values())
    frames = []
    with bullet_character(skeleton) as (cid, body):
        up = skeleton.up_axis
        target = [0.0, 0.0, 0.0]
        target[up] = -0.1  # the middle of a standing humanoid is a little below its root
        view = pb.computeViewMatrixFromYawPitchRoll(
            cameraTargetPosition=target, distance=distance, yaw=yaw, pitch=pitch, roll=0.0,
            upAxisIndex=up, physicsClientId=cid)  # fmt: skip
        proj = pb.computeProjectionMatrixFOV(fov=60.0, aspect=width / height, nearVal=0.05, farVal=50.0,
                                             physicsClientId=cid)  # fmt: skip
        for q in joints:
            pb.resetBasePositionAndOrientation(body, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0], physicsClientId=cid)
            pb.resetJointStatesMultiDof(body, indices, [q[s].tolist() for s in slices], physicsClientId=cid)
            _, _, rgba, _, _ = pb.getCameraImage(width, height, view, proj, renderer=pb.ER_TINY_RENDERER,
                                                 physicsClientId=cid)  # fmt: skip
            frames.append(np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3].copy())
    return frames
