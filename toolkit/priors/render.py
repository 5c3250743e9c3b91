"""Pictures of decoded poses: pose the character in a PyBullet DIRECT client, render each pose with
TinyRenderer (no display), tile the frames into one PNG filmstrip.

Still poses are set here directly (no simulation needed); tiling uses ``toolkit.render``, which the
simulator shares.
The camera looks at the root from the character's right side (+z in the DeepMimic y-up world).
"""

from __future__ import annotations

from pathlib import Path
import numpy as np

from toolkit.motion.skeletons import Skeleton
from toolkit.render import filmstrip


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

    from toolkit.motion.kinematics import bullet_character

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


def save_filmstrip(skeleton: Skeleton, dofs: np.ndarray, path: str | Path, columns: int = 0) -> Path:
    """Render poses ``(n, n_dof)`` and write them as one PNG filmstrip."""
    import imageio.v3 as iio

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    iio.imwrite(path, filmstrip(render_poses(skeleton, dofs), columns))
    return path
