"""Articulated-body ``Model`` and its per-call ``Data`` workspace.

A simulator plugin builds the ``Model`` of a body once from its engine (``sim=bullet``:
``model_from_bullet`` of its ``model`` module); nothing here reads a simulator.

The split follows Pinocchio: a ``Model`` is immutable topology + inertial parameters flattened
into numpy arrays that numba kernels consume; a ``Data`` holds every buffer an algorithm writes,
so a call allocates nothing. One ``Data`` per thread.

Bodies and frames:
    * Body 0 is the base; bodies ``1..n_bodies-1`` are the movable PyBullet links in link order
      (a parent always precedes its children). Links attached by fixed joints are merged into
      their parent body (mass, centre of mass and inertia combined).
    * A body's frame sits at its joint's pivot (the URDF link origin) with the orientation of the
      link's PyBullet frame, which is its *inertial* frame (centre of mass, principal axes): that
      is the frame btMultiBody rotates joints in (``getJointInfo`` axes and spherical quaternions
      are expressed in it). The base's frame is its inertial frame
      (``getBasePositionAndOrientation`` reports that frame, so the floating-base coordinates
      below are PyBullet's).

Generalised coordinates (the same as PyBullet's ``getJointStatesMultiDof`` / ``getBase*``):
    * ``q`` ``(n_q,)``: for a floating base the base inertial-frame position (3) and orientation
      quaternion ``x, y, z, w`` (4), world frame; then per movable joint in link order a quaternion
      ``x, y, z, w`` (spherical: child inertial frame relative to its pose at q = 0) or one scalar
      (revolute angle / prismatic displacement along the joint axis).
    * ``qd`` ``(n_v,)``: base linear velocity of the base inertial-frame origin and base angular
      velocity, both in world coordinates (``getBaseVelocity``); then per joint 3 (spherical:
      angular velocity of the child relative to the parent, in *child* coordinates) or 1 entries.
    * Generalised forces use the same layout as ``qd``: for the base, a world force at the base
      inertial-frame origin then a world torque; for a spherical joint the torque in child
      coordinates (what ``setJointMotorControlMultiDof(..., TORQUE_CONTROL)`` applies).

These were checked against PyBullet (``toolkit/dynamics`` tests): one ``stepSimulation`` from any
state reproduces ``qd + dt * aba(q, qd, tau)`` to ~1e-12 for every character.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from toolkit.dynamics.spatial import spatial_inertia

# joint types (column JTYPE of Model.mi)
JT_FIXED_BASE = 0  #: body 0 of a fixed-base model (no DoF)
JT_FREE = 1  #: body 0 of a floating-base model (6 DoF)
JT_REVOLUTE = 2
JT_PRISMATIC = 3
JT_SPHERICAL = 4

# packed integer columns (Model.mi)
MI_PARENT, MI_JTYPE, MI_QI, MI_VI, MI_NV = 0, 1, 2, 3, 4
MI_COLS = 5
# packed float columns (Model.mf): tree rotation (row-major), tree translation, axis, inertia
MF_TR, MF_TP, MF_AX, MF_IN = 0, 9, 12, 15
MF_COLS = 51

# per-body workspace columns (Data.wb)
W_XE, W_XR, W_V, W_C, W_A, W_F = 0, 9, 12, 18, 24, 30  # X (E, r), v, c = v x vJ, a, f
W_IA, W_PA, W_U, W_DI, W_UV = 36, 72, 78, 96, 105  # I^A, p^A, U (6x3), D^-1 (3x3), u
W_COLS = 108
# rows of the per-DoF workspace (Data.wv)
V_TAU, V_QDD, V_BIAS, V_Q, V_K, V_R, V_Z, V_P, V_AP, V_PRE, V_EXT, V_RHS = range(12)
V_ROWS = 12

def quat_matrix(q: Any) -> np.ndarray:
    """Rotation matrix ``(3, 3)`` of a unit quaternion ``x, y, z, w``."""
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def shift_inertia(I_c: np.ndarray, m: float, d: np.ndarray) -> np.ndarray:
    """Parallel-axis theorem: inertia about a point at offset ``-d`` from the centre of mass."""
    return I_c + m * (float(d @ d) * np.eye(3) - np.outer(d, d))


@dataclasses.dataclass(eq=False)
class Model:
    """Kinematic tree with inertial parameters, flattened for numba kernels.

    Attributes:
        name: body name (URDF robot name or what the caller passed).
        floating: whether the base has 6 DoF.
        n_bodies: number of bodies after merging fixed links (base included).
        n_q: length of ``q``.
        n_v: length of ``qd`` / ``tau``.
        parent: parent body ``(n_bodies,)``, -1 for the base.
        jtype: joint type ``(n_bodies,)`` (``JT_*``).
        q_idx: first index of each body's joint in ``q`` ``(n_bodies,)``.
        v_idx: first index of each body's joint in ``qd`` ``(n_bodies,)``.
        nv: DoFs of each body's joint ``(n_bodies,)``.
        axis: joint axis in the body frame ``(n_bodies, 3)`` (revolute / prismatic).
        tree_R: joint-frame orientation in the parent body frame ``(n_bodies, 3, 3)``; for a fixed
            base, row 0 is the base's world orientation.
        tree_p: joint-frame origin in the parent body frame ``(n_bodies, 3)``; for a fixed base,
            row 0 is the base's world position.
        mass: body masses ``(n_bodies,)``.
        com: centres of mass in body frames ``(n_bodies, 3)``.
        I_com: rotational inertias about the centres of mass, body axes ``(n_bodies, 3, 3)``.
        inertia: spatial inertias about the body-frame origins ``(n_bodies, 6, 6)``.
        dof_parent: parent DoF of each DoF ``(n_v,)`` (Featherstone's lambda for sparse LTL).
        depth: the most DoFs on a root-to-leaf path (thesis Table 2.1's ``d``).
        gravity: gravity acceleration, world frame ``(3,)``.
        joint_indices: PyBullet joint index of bodies ``1..`` ``(n_bodies - 1,)``.
        joint_nq: ``q`` entries of each PyBullet joint in ``joint_indices`` ``(n_bodies - 1,)``.
        link_body: body that each PyBullet link belongs to ``(n_links,)`` (-1 = the base link).
        link_R: orientation of each PyBullet link frame (its inertial frame) in its body frame
            ``(n_links, 3, 3)``.
        link_p: origin of each PyBullet link frame (its centre of mass) in its body frame
            ``(n_links, 3)``.
        body_names: link name of each body ``(n_bodies,)``.
        mi: packed integer table ``(n_bodies, MI_COLS)``.
        mf: packed float table ``(n_bodies, MF_COLS)``.
    """

    name: str
    floating: bool
    parent: np.ndarray
    jtype: np.ndarray
    axis: np.ndarray
    tree_R: np.ndarray
    tree_p: np.ndarray
    mass: np.ndarray
    com: np.ndarray
    I_com: np.ndarray
    gravity: np.ndarray
    joint_indices: np.ndarray
    link_body: np.ndarray
    link_R: np.ndarray
    link_p: np.ndarray
    body_names: list[str]
    n_bodies: int = 0
    n_q: int = 0
    n_v: int = 0
    q_idx: np.ndarray = None  # type: ignore[assignment]
    v_idx: np.ndarray = None  # type: ignore[assignment]
    nv: np.ndarray = None  # type: ignore[assignment]
    joint_nq: np.ndarray = None  # type: ignore[assignment]
    inertia: np.ndarray = None  # type: ignore[assignment]
    dof_parent: np.ndarray = None  # type: ignore[assignment]
    depth: int = 0
    mi: np.ndarray = None  # type: ignore[assignment]
    mf: np.ndarray = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        nb = len(self.parent)
        self.n_bodies = nb
        nq_of = {JT_FIXED_BASE: 0, JT_FREE: 7, JT_REVOLUTE: 1, JT_PRISMATIC: 1, JT_SPHERICAL: 4}
        nv_of = {JT_FIXED_BASE: 0, JT_FREE: 6, JT_REVOLUTE: 1, JT_PRISMATIC: 1, JT_SPHERICAL: 3}
        self.q_idx = np.zeros(nb, dtype=np.int64)
        self.v_idx = np.zeros(nb, dtype=np.int64)
        self.nv = np.zeros(nb, dtype=np.int64)
        iq = iv = 0
        for i, t in enumerate(self.jtype):
            self.q_idx[i], self.v_idx[i], self.nv[i] = iq, iv, nv_of[int(t)]
            iq += nq_of[int(t)]
            iv += nv_of[int(t)]
        self.n_q, self.n_v = iq, iv
        self.joint_nq = np.array([nq_of[int(t)] for t in self.jtype[1:]], dtype=np.int64)
        self.inertia = np.stack([spatial_inertia(m, c, I)
                                 for m, c, I in zip(self.mass, self.com, self.I_com)])
        # DoF-level parents: within a joint DoF k's parent is DoF k-1; a joint's first DoF hangs
        # from the last DoF of the nearest ancestor that has DoFs.
        self.dof_parent = np.full(iv, -1, dtype=np.int64)
        depth = np.zeros(nb, dtype=np.int64)
        for i in range(nb):
            a = self.parent[i]
            while a >= 0 and self.nv[a] == 0:
                a = self.parent[a]
            last = self.v_idx[a] + self.nv[a] - 1 if a >= 0 else -1
            for k in range(self.nv[i]):
                self.dof_parent[self.v_idx[i] + k] = last if k == 0 else self.v_idx[i] + k - 1
            depth[i] = (depth[self.parent[i]] if self.parent[i] >= 0 else 0) + self.nv[i]
        self.depth = int(depth.max())
        self.mi = np.zeros((nb, MI_COLS), dtype=np.int64)
        self.mi[:, MI_PARENT] = self.parent
        self.mi[:, MI_JTYPE] = self.jtype
        self.mi[:, MI_QI] = self.q_idx
        self.mi[:, MI_VI] = self.v_idx
        self.mi[:, MI_NV] = self.nv
        self.mf = np.zeros((nb, MF_COLS))
        self.mf[:, MF_TR:MF_TR + 9] = self.tree_R.reshape(nb, 9)
        self.mf[:, MF_TP:MF_TP + 3] = self.tree_p
        self.mf[:, MF_AX:MF_AX + 3] = self.axis
        self.mf[:, MF_IN:MF_IN + 36] = self.inertia.reshape(nb, 36)

    def set_base_pose(self, position: Any, orientation: Any) -> None:
        """World pose of a fixed base (position ``(3,)``, quaternion ``x, y, z, w``)."""
        if self.floating:
            raise ValueError("set_base_pose is for fixed-base models; a floating base pose is in q")
        self.tree_R[0] = quat_matrix(orientation)
        self.tree_p[0] = np.asarray(position, dtype=float)
        self.mf[0, MF_TR:MF_TR + 9] = self.tree_R[0].ravel()
        self.mf[0, MF_TP:MF_TP + 3] = self.tree_p[0]

    def neutral(self) -> np.ndarray:
        """Neutral configuration ``q`` ``(n_q,)``: identity quaternions, zero scalars."""
        q = np.zeros(self.n_q)
        for i, t in enumerate(self.jtype):
            if t == JT_FREE:
                q[self.q_idx[i] + 6] = 1.0
            elif t == JT_SPHERICAL:
                q[self.q_idx[i] + 3] = 1.0
        return q

    def random_state(self, rng: np.random.Generator,
                     scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """A random ``(q, qd)``: uniform unit quaternions, normal scalars and velocities * scale."""
        q = np.zeros(self.n_q)
        for i, t in enumerate(self.jtype):
            k = self.q_idx[i]
            if t == JT_FREE:
                q[k:k + 3] = rng.normal(size=3)
                u = rng.normal(size=4)
                q[k + 3:k + 7] = u / np.linalg.norm(u)
            elif t == JT_SPHERICAL:
                u = rng.normal(size=4)
                q[k:k + 4] = u / np.linalg.norm(u)
            elif t in (JT_REVOLUTE, JT_PRISMATIC):
                q[k] = scale * rng.normal()
        return q, scale * rng.normal(size=self.n_v)


class Data:
    """Workspace for one model: every buffer the algorithms write (no allocation per call).

    Attributes:
        wb: per-body workspace ``(n_bodies, W_COLS)`` (transforms, velocities, inertias ...).
        wv: per-DoF vectors ``(V_ROWS, n_v)`` (``V_TAU``, ``V_QDD``, ``V_BIAS`` ...).
        H: mass matrix ``(n_v, n_v)`` written by CRBA (only ancestor pairs are ever non-zero).
        A: factorisation buffer ``(n_v, n_v)``.
        sc: scratch ``(256,)``.
        tau: last generalised forces ``(n_v,)`` (view of ``wv[V_TAU]``).
        qdd: last accelerations ``(n_v,)`` (view of ``wv[V_QDD]``).
        iterations: PCG iterations of the last ``pcg`` solve.
    """

    def __init__(self, model: Model) -> None:
        self.wb = np.zeros((model.n_bodies, W_COLS))
        self.wv = np.zeros((V_ROWS, model.n_v))
        self.H = np.zeros((model.n_v, model.n_v))
        self.A = np.zeros((model.n_v, model.n_v))
        self.sc = np.zeros(256)
        self.zeros_v = np.zeros(model.n_v)
        self.tau = self.wv[V_TAU]
        self.qdd = self.wv[V_QDD]
        self.iterations = 0
