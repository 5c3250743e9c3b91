"""Pose features for the pose priors and the get-up conditions.

* ``pose_features`` — the P-VAE input of ``000`` §4.2: "all link and joint positions relative
  to the root in the local root frames, and all joint rotations with respect to their parents",
  rotations in 6D (Zhou et al. 2019). Positions are in the root (pelvis) frame, not a heading
  frame, as the paper says. Points that are constant in the root frame (the root link's COM, the
  joint origins of the root's children) carry no information and are left out.
  Revolute joints are 6D too (of the rotation about their axis) so every joint is encoded alike.
* ``getup_conditions`` — the C-VAE condition ``c = (h, theta_side, theta_front)`` of ``003``
  §3.3.1, §3.5 and §4.2 (Fig. 4): height of the neck base above the ground; angle between the
  torso side vector and global up; angle between the torso front vector and global up. The side
  vector points from the left to the right hip joint ("oriented with the hips and directed to
  the character's right side", §3.1); the front vector is ``(neck - hips) x side`` normalised
  ("the cross product of the vector connecting the neck and hips and the side vector"), hips
  being the midpoint of the two hip joints. Standing upright gives ``(~1.3 m, pi/2, pi/2)``;
  lying face up gives a front angle near 0, face down near ``pi``.
"""

from __future__ import annotations

import dataclasses
import json
from typing import TYPE_CHECKING

import numpy as np

from toolkit.motion import rotations as rot
from toolkit.motion.kinematics import Kinematics, forward_kinematics
from toolkit.motion.skeletons import SKELETONS, SPHERICAL, Skeleton

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.motion.clips import Clip

CONDITION_NAMES = ("neck_height", "side_torso_angle", "front_torso_angle")


@dataclasses.dataclass(frozen=True)
class FeatureBlock:
    """Columns ``[start, stop)`` of a feature row: one point (3) or one joint rotation (6).

    Attributes:
        name: link or joint name.
        kind: ``"joint_pos"`` (link frame origin), ``"link_com"`` (link centre of mass) or
            ``"rot6d"`` (joint rotation relative to its parent, 6D).
    """

    name: str
    kind: str
    start: int
    stop: int


@dataclasses.dataclass(frozen=True)
class FeatureLayout:
    """Describes the columns of ``pose_features`` output.

    Attributes:
        skeleton: skeleton name.
        frame: frame the positions are expressed in (``"root"``).
        blocks: column blocks in order.
    """

    skeleton: str
    frame: str
    blocks: tuple[FeatureBlock, ...]

    @property
    def size(self) -> int:
        return self.blocks[-1].stop if self.blocks else 0

    def columns(self, kind: str) -> np.ndarray:
        """Column indices of every block of ``kind``."""
        return np.concatenate([np.arange(b.start, b.stop) for b in self.blocks if b.kind == kind] or [np.zeros(0, int)])

    def block(self, name: str, kind: str) -> slice:
        for b in self.blocks:
            if b.name == name and b.kind == kind:
                return slice(b.start, b.stop)
        raise KeyError(f"no {kind} block for {name!r}")

    def to_json(self) -> str:
        return json.dumps({"skeleton": self.skeleton, "frame": self.frame,
                           "blocks": [dataclasses.astuple(b) for b in self.blocks]})  # fmt: skip

    @classmethod
    def from_json(cls, text: str) -> "FeatureLayout":
        d = json.loads(text)
        return cls(d["skeleton"], d["frame"], tuple(FeatureBlock(*b) for b in d["blocks"]))


def feature_layout(skeleton: Skeleton) -> FeatureLayout:
    """The column layout ``pose_features`` produces for ``skeleton``."""
    rigid = {skeleton.link_index(n) for n in skeleton.root_rigid} | {-1}
    blocks, i = [], 0
    for k, name in enumerate(skeleton.links):
        if skeleton.link_parents[k] not in rigid:
            blocks.append(FeatureBlock(name, "joint_pos", i, i + 3))
            i += 3
    for k, name in enumerate(skeleton.links):
        if k not in rigid:
            blocks.append(FeatureBlock(name, "link_com", i, i + 3))
            i += 3
    for j in skeleton.joints:
        blocks.append(FeatureBlock(j.name, "rot6d", i, i + 6))
        i += 6
    return FeatureLayout(skeleton.name, "root", tuple(blocks))


def _joint_matrices(skeleton: Skeleton, joints: np.ndarray) -> list[np.ndarray]:
    mats = []
    for j, s in zip(skeleton.joints, skeleton.q_slices.values()):
        if j.kind == SPHERICAL:
            mats.append(rot.quat_to_matrix(joints[:, s]))
        else:
            mats.append(rot.quat_to_matrix(rot.quat_from_axis_angle(np.array(j.axis), joints[:, s.start])))
    return mats


def pose_features(
    skeleton: Skeleton,
    root_pos: np.ndarray,
    root_rot: np.ndarray,
    joints: np.ndarray,
    kin: Kinematics | None = None,
) -> tuple[np.ndarray, FeatureLayout]:
    """Pose features of ``000`` §4.2 for each pose.

    Args:
        skeleton: the character.
        root_pos: root positions ``(n, 3)``.
        root_rot: root orientations ``x, y, z, w`` ``(n, 4)``.
        joints: poses in the quaternion layout ``(n, n_q)``.
        kin: forward kinematics of these poses; computed with PyBullet when omitted.

    Returns:
        features ``(n, layout.size)`` and the layout.
    """
    root_pos = np.atleast_2d(np.asarray(root_pos, dtype=np.float64))
    root_rot = np.atleast_2d(np.asarray(root_rot, dtype=np.float64))
    joints = np.atleast_2d(np.asarray(joints, dtype=np.float64))
    if kin is None:
        kin = forward_kinematics(skeleton, root_pos, root_rot, joints)
    layout = feature_layout(skeleton)
    inv = rot.quat_conjugate(root_rot)[:, None, :]
    local = {
        "joint_pos": rot.quat_rotate(inv, kin.joint_pos - root_pos[:, None, :]),
        "link_com": rot.quat_rotate(inv, kin.link_com - root_pos[:, None, :]),
    }
    mats = dict(zip(skeleton.joint_names, _joint_matrices(skeleton, joints)))
    out = np.empty((root_pos.shape[0], layout.size))
    for b in layout.blocks:
        if b.kind == "rot6d":
            out[:, b.start : b.stop] = rot.matrix_to_6d(mats[b.name])
        else:
            out[:, b.start : b.stop] = local[b.kind][:, skeleton.link_index(b.name)]
    return out, layout


def features_to_joints(features: np.ndarray, layout: FeatureLayout) -> np.ndarray:
    """Joint rotations ``(..., n_q)`` decoded from the 6D blocks of features ``(..., size)``.

    Spherical joints: Gram-Schmidt then quaternion. Revolute joints: the angle about the joint
    axis of the decoded rotation (``atan2`` of a perpendicular vector's turn), so a decoder's
    output that is not exactly a rotation about the axis is projected onto it.
    """
    sk = SKELETONS[layout.skeleton]
    features = np.asarray(features, dtype=np.float64)
    out = np.empty(features.shape[:-1] + (sk.n_q,))
    for j, s in zip(sk.joints, sk.q_slices.values()):
        m = rot.sixd_to_matrix(features[..., layout.block(j.name, "rot6d")])
        if j.kind == SPHERICAL:
            out[..., s] = rot.matrix_to_quat(m)
        else:
            a = np.asarray(j.axis, dtype=np.float64)
            e = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
            e /= np.linalg.norm(e)
            re = m @ e
            out[..., s.start] = np.arctan2(re @ np.cross(a, e), re @ e)
    return out


def _angle_to(v: np.ndarray, up: np.ndarray) -> np.ndarray:
    return np.arctan2(np.linalg.norm(np.cross(v, up), axis=-1), v @ up)


def getup_conditions(skeleton: Skeleton, kin: Kinematics, ground_height: float = 0.0) -> np.ndarray:
    """C-VAE conditions ``(h, theta_side, theta_front)`` of ``003`` for each pose ``(n, 3)``.

    Args:
        skeleton: the character (must name ``neck_link`` and ``hip_links``).
        kin: forward kinematics of the poses.
        ground_height: ground level along the up axis (flat ground; the paper averages a height map).
    """
    if skeleton.neck_link is None or skeleton.hip_links is None:
        raise ValueError(f"skeleton {skeleton.name} has no neck / hip links for get-up conditions")
    up = np.zeros(3)
    up[skeleton.up_axis] = 1.0
    neck = kin.joint_pos[:, kin.index(skeleton.neck_link)]
    r_hip = kin.joint_pos[:, kin.index(skeleton.hip_links[0])]
    l_hip = kin.joint_pos[:, kin.index(skeleton.hip_links[1])]
    side = r_hip - l_hip
    side /= np.linalg.norm(side, axis=-1, keepdims=True)
    front = np.cross(neck - 0.5 * (r_hip + l_hip), side)
    front /= np.linalg.norm(front, axis=-1, keepdims=True)
    height = neck[:, skeleton.up_axis] - ground_height
    return np.stack([height, _angle_to(side, up), _angle_to(front, up)], axis=-1)


def clip_features(clip: "Clip", ground_height: float = 0.0) -> tuple[np.ndarray, np.ndarray, FeatureLayout]:
    """Pose features ``(n_frames, size)``, get-up conditions ``(n_frames, 3)`` and the layout of a
    clip's frames (one forward-kinematics pass for both)."""
    kin = clip.fk()
    feats, layout = pose_features(clip.skeleton, clip.root_pos, clip.root_rot, clip.joints, kin)
    return feats, getup_conditions(clip.skeleton, kin, ground_height), layout
