"""Joint tables of the characters whose mocap jt reads (DeepMimic humanoid, Laikago).

A pose's internal joints are stored in one flat row, the *quaternion layout*: each spherical
joint takes 4 values (a local rotation ``x, y, z, w`` of the child frame relative to the parent
joint frame, as PyBullet's ``resetJointStatesMultiDof`` takes it) and each revolute joint 1 (its
URDF angle in radians), in the order of ``Skeleton.joints``. The *dof layout* is the same with 3
values (exponential map) per spherical joint: it is the PD-target layout (28 DoFs for the humanoid).
"""

from __future__ import annotations

import dataclasses
import functools
import os

import numpy as np

from toolkit.motion import rotations as rot

SPHERICAL = "spherical"
REVOLUTE = "revolute"


@dataclasses.dataclass(frozen=True)
class JointSpec:
    """One internal joint.

    Attributes:
        name: joint name (the URDF joint / child-link name).
        kind: ``"spherical"`` or ``"revolute"``.
        bullet_index: PyBullet joint index (= child link index) with ``URDF_MAINTAIN_LINK_ORDER``.
        mirror: name of the joint that this one becomes under left/right mirroring.
        axis: revolute axis in the joint frame (unused for spherical joints).
        file_direction: URDF angle = ``file_direction * file value + file_offset`` (Laikago mocap
            stores angles with signs and offsets that differ from its URDF; 1 and 0 otherwise).
        file_offset: see ``file_direction``.
    """

    name: str
    kind: str
    bullet_index: int
    mirror: str
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    file_direction: float = 1.0
    file_offset: float = 0.0

    @property
    def n_q(self) -> int:
        return 4 if self.kind == SPHERICAL else 1

    @property
    def n_dof(self) -> int:
        return 3 if self.kind == SPHERICAL else 1


@dataclasses.dataclass(frozen=True)
class Skeleton:
    """A character's joint table, link table and axes.

    Attributes:
        name: ``"humanoid"`` or ``"laikago"``.
        urdf: URDF path relative to ``data_dir()``; ``urdf_path`` is the full path.
        scale: ``globalScaling`` to load the URDF with.
        joints: internal joints in file / layout order.
        links: PyBullet link names by link index (the base, index -1, is not listed).
        link_parents: parent link index of each link (-1 = base).
        link_mirror: name of each link's mirror image.
        root_rigid: links rigidly fixed to the base (their pose in the root frame is constant).
        up_axis: world up axis of the data (1 = y for DeepMimic, 2 = z for Laikago).
        lateral_axis: axis normal to the sagittal plane, the same index in the body (URDF) frame
            and the world frame; mirroring reflects it.
        root_quat_order: order of the root quaternion in the file, ``"wxyz"`` or ``"xyzw"``.
        neck_link: link whose frame origin is the base of the neck (``003`` §3.1), if any.
        hip_links: (right, left) hip links, whose joint origins give the hips' position and side.
    """

    name: str
    urdf: str
    scale: float
    joints: tuple[JointSpec, ...]
    links: tuple[str, ...]
    link_parents: tuple[int, ...]
    link_mirror: tuple[str, ...]
    root_rigid: tuple[str, ...]
    up_axis: int
    lateral_axis: int
    root_quat_order: str
    neck_link: str | None = None
    hip_links: tuple[str, str] | None = None

    @property
    def urdf_path(self) -> str:
        """Full path of the character's URDF."""
        return os.path.join(data_dir(), self.urdf)

    # ----------------------------------------------------------------- layout bookkeeping
    @property
    def joint_names(self) -> list[str]:
        return [j.name for j in self.joints]

    @functools.cached_property
    def n_q(self) -> int:
        """Width of the quaternion layout."""
        return sum(j.n_q for j in self.joints)

    @functools.cached_property
    def n_dof(self) -> int:
        """Width of the dof layout (internal DoFs; cached: every action checks its size with it)."""
        return sum(j.n_dof for j in self.joints)

    @property
    def frame_size(self) -> int:
        """Floats per frame in a DeepMimic-format file: duration, root pos, root quat, joints."""
        return 1 + 3 + 4 + self.n_q

    def _slices(self, attr: str) -> dict[str, slice]:
        out, i = {}, 0
        for j in self.joints:
            n = getattr(j, attr)
            out[j.name] = slice(i, i + n)
            i += n
        return out

    @property
    def q_slices(self) -> dict[str, slice]:
        """Joint name → slice of the quaternion layout."""
        return self._slices("n_q")

    @property
    def dof_slices(self) -> dict[str, slice]:
        """Joint name → slice of the dof layout."""
        return self._slices("n_dof")

    def joint(self, name: str) -> JointSpec:
        for j in self.joints:
            if j.name == name:
                return j
        raise KeyError(f"{self.name} has no joint {name!r}")

    def link_index(self, name: str) -> int:
        return self.links.index(name)

    def mirror_link_index(self) -> np.ndarray:
        """Link index → index of its mirror image ``(n_links,)``."""
        return np.array([self.links.index(n) for n in self.link_mirror])

    # ----------------------------------------------------------------- conversions
    def rest_joints(self, shape: tuple[int, ...] = ()) -> np.ndarray:
        """The zero pose ``(*shape, n_q)`` (identity rotations, zero angles)."""
        out = np.zeros(tuple(shape) + (self.n_q,))
        for j, s in zip(self.joints, self.q_slices.values()):
            if j.kind == SPHERICAL:
                out[..., s.stop - 1] = 1.0
        return out

    def joints_to_dofs(self, joints: np.ndarray) -> np.ndarray:
        """Quaternion layout ``(..., n_q)`` → dof layout ``(..., n_dof)`` (exp maps, angles)."""
        joints = np.asarray(joints, dtype=np.float64)
        parts = []
        for j, s in zip(self.joints, self.q_slices.values()):
            parts.append(rot.quat_to_expmap(joints[..., s]) if j.kind == SPHERICAL else joints[..., s])
        return np.concatenate(parts, axis=-1)

    def dofs_to_joints(self, dofs: np.ndarray) -> np.ndarray:
        """Dof layout ``(..., n_dof)`` → quaternion layout ``(..., n_q)``: every spherical joint's
        exp map through one ``quat_from_expmap`` call (the per-step hot path of every action space)."""
        dofs = np.asarray(dofs, dtype=np.float64)
        sph_dof, sph_q, rev_dof, rev_q = self._conversion_columns()
        if dofs.ndim == 1 and dofs.shape[0] == self.n_dof:  # one pose: compiled, the same bits
            from toolkit.motion import kernels

            out = np.empty(self.n_q)
            kernels.dofs_to_joints(dofs, sph_dof, sph_q, rev_dof, rev_q, out)
            return out
        out = np.empty(dofs.shape[:-1] + (self.n_q,))
        out[..., rev_q] = dofs[..., rev_dof]
        if len(sph_dof):
            out[..., sph_q] = rot.quat_from_expmap(dofs[..., sph_dof])
        return out

    def _conversion_columns(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Dof columns ``(n_spherical, 3)`` and quaternion columns ``(n_spherical, 4)`` of the
        spherical joints, dof and quaternion columns ``(n_revolute,)`` of the others (cached)."""
        cached = self.__dict__.get("_columns")
        if cached is None:
            sph_dof, sph_q, rev_dof, rev_q = [], [], [], []
            for j, sd, sq in zip(self.joints, self.dof_slices.values(), self.q_slices.values()):
                if j.kind == SPHERICAL:
                    sph_dof.append(list(range(sd.start, sd.stop)))
                    sph_q.append(list(range(sq.start, sq.stop)))
                else:
                    rev_dof += list(range(sd.start, sd.stop))
                    rev_q += list(range(sq.start, sq.stop))
            cached = (np.array(sph_dof, dtype=int).reshape(-1, 3), np.array(sph_q, dtype=int).reshape(-1, 4),
                      np.array(rev_dof, dtype=int), np.array(rev_q, dtype=int))
            object.__setattr__(self, "_columns", cached)
        return cached

    def reflect_quat(self, q: np.ndarray) -> np.ndarray:
        """Reflect rotations ``(..., 4)`` across the sagittal plane: ``M R M``, ``M`` = diag with
        -1 on ``lateral_axis``. The vector part becomes ``-M v``."""
        q = np.array(q, dtype=np.float64, copy=True)
        for k in range(3):
            if k != self.lateral_axis:
                q[..., k] = -q[..., k]
        return q

    def mirror_joints(self, joints: np.ndarray) -> np.ndarray:
        """Left/right mirror of poses in the quaternion layout ``(..., n_q)``.

        Each joint takes the reflected rotation of its mirror partner. A revolute angle maps by
        the sign ``-(M a_src) · a_dst`` (``+1`` when the axis is lateral, ``-1`` when it lies in
        the sagittal plane), which holds because left and right joint frames of both skeletons are
        mirror images with identity orientation.
        """
        joints = np.asarray(joints, dtype=np.float64)
        out = np.empty_like(joints)
        qs = self.q_slices
        for j in self.joints:
            src = self.joint(j.mirror)
            val = joints[..., qs[src.name]]
            if j.kind == SPHERICAL:
                out[..., qs[j.name]] = self.reflect_quat(val)
            else:
                m_a = np.array(src.axis, dtype=np.float64)
                m_a[self.lateral_axis] *= -1.0
                out[..., qs[j.name]] = -float(m_a @ np.array(j.axis)) * val
        return out


def _humanoid() -> Skeleton:
    s, r = SPHERICAL, REVOLUTE
    table = [  # (name, kind, bullet index) in DeepMimic file order
        ("chest", s, 1), ("neck", s, 2),
        ("right_hip", s, 3), ("right_knee", r, 4), ("right_ankle", s, 5),
        ("right_shoulder", s, 6), ("right_elbow", r, 7),
        ("left_hip", s, 9), ("left_knee", r, 10), ("left_ankle", s, 11),
        ("left_shoulder", s, 12), ("left_elbow", r, 13),
    ]  # fmt: skip

    def partner(n: str) -> str:
        return n.replace("right_", "left_") if n.startswith("right_") else n.replace("left_", "right_")

    joints = tuple(JointSpec(n, k, i, partner(n)) for n, k, i in table)
    links = ("root", "chest", "neck", "right_hip", "right_knee", "right_ankle", "right_shoulder",
             "right_elbow", "right_wrist", "left_hip", "left_knee", "left_ankle", "left_shoulder",
             "left_elbow", "left_wrist")  # fmt: skip
    parents = (-1, 0, 1, 0, 3, 4, 1, 6, 7, 0, 9, 10, 1, 12, 13)
    return Skeleton(
        name="humanoid", urdf="humanoid/humanoid.urdf", scale=0.25, joints=joints, links=links,
        link_parents=parents, link_mirror=tuple(partner(n) for n in links), root_rigid=("root",),
        up_axis=1, lateral_axis=2,
        root_quat_order="wxyz", neck_link="neck", hip_links=("right_hip", "left_hip"),
    )  # fmt: skip


def _laikago() -> Skeleton:
    # PyBullet's deep_mimic/testLaikago.py: URDF angle = direction * mocap value + offset.
    direction = [-1, 1, 1, 1, 1, 1, -1, 1, 1, 1, 1, 1]
    offset = [0.0, -0.7, 0.7] * 4
    mirror = {"FR": "FL", "FL": "FR", "RR": "RL", "RL": "RR"}
    joints, links, parents, link_mirror = [], [], [], []
    for li, leg in enumerate(("FR", "FL", "RR", "RL")):
        for pi, part in enumerate(("hip_motor", "upper_leg", "lower_leg")):
            k = 3 * li + pi
            # abduction about the forward (model z) axis, signed per side; flexion about lateral x
            axis = ((0.0, 0.0, -1.0 if leg[1] == "R" else 1.0) if pi == 0 else (1.0, 0.0, 0.0))
            joints.append(JointSpec(f"{leg}_{part}", REVOLUTE, k, f"{mirror[leg]}_{part}", axis,
                                    float(direction[k]), offset[k]))
            links.append(f"{leg}_{part}")
            parents.append(-1 if pi == 0 else k - 1)
            link_mirror.append(f"{mirror[leg]}_{part}")
    # laikago_toes.urdf = laikago.urdf (used by the deep_mimic code) plus fixed toe links 12..15
    for leg in ("RL", "RR", "FL", "FR"):
        links.append(f"toe{leg}")
        parents.append(links.index(f"{leg}_lower_leg"))
        link_mirror.append(f"toe{mirror[leg]}")
    return Skeleton(
        name="laikago", urdf="laikago/laikago_toes.urdf", scale=1.0, joints=tuple(joints),
        links=tuple(links), link_parents=tuple(parents), link_mirror=tuple(link_mirror),
        root_rigid=(), up_axis=2, lateral_axis=0, root_quat_order="xyzw",
    )  # fmt: skip


HUMANOID = _humanoid()
LAIKAGO = _laikago()
SKELETONS = {"humanoid": HUMANOID, "laikago": LAIKAGO}


def data_dir() -> str:
    """Folder of the ``pybullet_data`` package (the characters' URDFs, the DeepMimic clips): a data
    location, found without importing anything (``pybullet_data.getDataPath()`` is this folder)."""
    import importlib.util

    spec = importlib.util.find_spec("pybullet_data")
    if spec is None or not spec.submodule_search_locations:
        raise FileNotFoundError("the pybullet_data package (jt's mocap clips and URDFs) is not installed")
    return str(list(spec.submodule_search_locations)[0])


def motions_dir() -> str:
    """Folder of the DeepMimic-format clips shipped with ``pybullet_data``."""
    return os.path.join(data_dir(), "data", "motions")


def humanoid_clip_paths() -> list[str]:
    """Sorted paths of every ``humanoid3d_*.txt`` clip in ``pybullet_data``."""
    d = motions_dir()
    return sorted(os.path.join(d, f) for f in os.listdir(d) if f.startswith("humanoid3d_") and f.endswith(".txt"))
