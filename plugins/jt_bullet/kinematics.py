"""Forward kinematics of mocap poses by PyBullet: the engine behind ``toolkit.motion.kinematics``.

``BulletSimulator.forward_kinematics``, ``kinematic_body`` and ``render_poses`` (the optional
``Simulator`` hooks) are these: the character's URDF in a private DIRECT client, never stepped,
posed with ``resetBasePositionAndOrientation`` / ``resetJointStatesMultiDof`` and read with
``getLinkStates``: PyBullet is the reference, not a re-derivation.
"""

from __future__ import annotations

import contextlib
from typing import Iterator

import numpy as np

from toolkit.motion.kinematics import Kinematics
from toolkit.motion.skeletons import Skeleton


@contextlib.contextmanager
def bullet_character(skeleton: Skeleton) -> Iterator[tuple[int, int]]:
    """A private PyBullet DIRECT client with the skeleton's URDF loaded.

    Yields:
        ``(client id, body id)``; the client is disconnected on exit.
    """
    import pybullet as pb

    from toolkit.motion.skeletons import data_dir

    cid = pb.connect(pb.DIRECT)
    try:
        pb.setAdditionalSearchPath(data_dir(), physicsClientId=cid)
        from toolkit.quiet import native_stderr_silenced

        with native_stderr_silenced():  # the DeepMimic URDF warns once per spherical joint
            body = pb.loadURDF(
                skeleton.urdf, globalScaling=skeleton.scale, useFixedBase=False,
                flags=pb.URDF_MAINTAIN_LINK_ORDER, physicsClientId=cid,
            )  # fmt: skip
        yield cid, body
    finally:
        pb.disconnect(cid)


def forward_kinematics(
    skeleton: Skeleton,
    root_pos: np.ndarray,
    root_rot: np.ndarray,
    joints: np.ndarray,
) -> Kinematics:
    """Link poses of each pose by PyBullet (``resetBasePositionAndOrientation``,
    ``resetJointStatesMultiDof``, ``getLinkStates``): PyBullet is the reference, not a re-derivation.

    Args:
        skeleton: the character.
        root_pos: root (base) positions ``(n, 3)``.
        root_rot: root orientations ``x, y, z, w`` ``(n, 4)``.
        joints: poses in the quaternion layout ``(n, n_q)``.

    Returns:
        ``Kinematics`` with arrays ``(n, n_links, ...)``.
    """
    import pybullet as pb

    root_pos = np.atleast_2d(np.asarray(root_pos, dtype=np.float64))
    root_rot = np.atleast_2d(np.asarray(root_rot, dtype=np.float64))
    joints = np.atleast_2d(np.asarray(joints, dtype=np.float64))
    n, n_links = root_pos.shape[0], len(skeleton.links)
    com = np.empty((n, n_links, 3))
    org = np.empty((n, n_links, 3))
    ori = np.empty((n, n_links, 4))
    indices = [j.bullet_index for j in skeleton.joints]
    slices = list(skeleton.q_slices.values())
    link_ids = list(range(n_links))
    with bullet_character(skeleton) as (cid, body):
        n_urdf = pb.getNumJoints(body, physicsClientId=cid)
        if n_urdf != n_links:
            raise RuntimeError(f"{skeleton.urdf} has {n_urdf} links, the {skeleton.name} table {n_links}")
        for i in range(n):
            pb.resetBasePositionAndOrientation(body, root_pos[i].tolist(), root_rot[i].tolist(), physicsClientId=cid)
            pb.resetJointStatesMultiDof(
                body, indices, [joints[i, s].tolist() for s in slices], physicsClientId=cid
            )
            states = pb.getLinkStates(body, link_ids, computeForwardKinematics=True, physicsClientId=cid)
            for k, st in enumerate(states):
                com[i, k] = st[0]
                org[i, k] = st[4]
                ori[i, k] = st[5]
    return Kinematics(tuple(skeleton.links), com, org, ori)


class KinematicBody:
    """A kinematic copy of a skeleton's character in a private PyBullet DIRECT client (never
    stepped): forward kinematics of poses for references and rewards.

    Args:
        skeleton: the character's skeleton (URDF, scale, joint layout).

    Attributes:
        masses: link masses ``(n_links + 1,)``, base first (kg).
    """

    def __init__(self, skeleton: Skeleton) -> None:
        import pybullet as pb

        self._pb = pb
        self._stack = contextlib.ExitStack()
        self.client, self.body = self._stack.enter_context(bullet_character(skeleton))
        kw = {"physicsClientId": self.client}
        n = pb.getNumJoints(self.body, **kw)
        self.masses = np.array([pb.getDynamicsInfo(self.body, i, **kw)[0] for i in range(-1, n)])
        self._indices = [j.bullet_index for j in skeleton.joints]
        self._slices = list(skeleton.q_slices.values())

    def pose(self, q: np.ndarray) -> None:
        """Put the copy in pose ``q`` ``(n_q,)`` (``toolkit.dynamics`` layout)."""
        pb, kw = self._pb, {"physicsClientId": self.client}
        q = np.asarray(q, dtype=float)
        pb.resetBasePositionAndOrientation(self.body, q[:3].tolist(), q[3:7].tolist(), **kw)
        pb.resetJointStatesMultiDof(self.body, self._indices, [q[7:][s].tolist() for s in self._slices], **kw)

    def lowest_point(self, q: np.ndarray, link: int | None = None) -> float:
        """Lowest height of a link's bounding box (None: of the whole body) in pose ``q``."""
        self.pose(q)
        pb, kw = self._pb, {"physicsClientId": self.client}
        links = [link] if link is not None else range(-1, len(self.masses) - 1)
        return float(min(pb.getAABB(self.body, i, **kw)[0][1] for i in links))

    def links_and_com(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Link centres of mass ``(n_links + 1, 3)`` (base first) and the CoM ``(3,)`` of pose ``q``."""
        q = np.asarray(q, dtype=float)
        self.pose(q)
        pb, kw = self._pb, {"physicsClientId": self.client}
        states = pb.getLinkStates(self.body, list(range(len(self.masses) - 1)), computeForwardKinematics=True, **kw)
        links = np.array([q[:3]] + [s[0] for s in states], dtype=float)
        return links, self.masses @ links / self.masses.sum()

    def close(self) -> None:
        """Disconnect the private client (idempotent)."""
        self._stack.close()
