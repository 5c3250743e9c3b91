"""Articulated-body ``Model`` (read once from a PyBullet body) and its per-call ``Data`` workspace.

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

_PB_REVOLUTE, _PB_PRISMATIC, _PB_SPHERICAL, _PB_FIXED = 0, 1, 2, 4


def _quat_rot(q: Any) -> np.ndarray:
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def _shift_inertia(I_c: np.ndarray, m: float, d: np.ndarray) -> np.ndarray:
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

    # --------------------------------------------------------------------------------------------
    @classmethod
    def from_bullet(cls, client: int, body_id: int, name: str | None = None,
                    gravity: Any = None, floating: bool | None = None) -> "Model":
        """Read a PyBullet multibody: joints, frames, masses, inertias, parents.

        Args:
            client: PyBullet physics client id.
            body_id: the body's unique id.
            name: model name (defaults to the URDF robot name).
            gravity: world gravity ``(3,)``; read from the client's physics parameters if None.
            floating: whether the base is free; PyBullet does not report it, so if None it is
                inferred from the size of ``calculateMassMatrix`` (falling back to "mass > 0").

        Returns:
            The model. For a fixed base, the base's current world pose is recorded (it only enters
            through the direction of gravity); call ``set_base_pose`` if the base is moved.
        """
        import pybullet as pb

        kw = {"physicsClientId": client}
        n_links = pb.getNumJoints(body_id, **kw)
        if name is None:
            name = pb.getBodyInfo(body_id, **kw)[1].decode()
        if gravity is None:
            par = pb.getPhysicsEngineParameters(**kw)
            gravity = [par["gravityAccelerationX"], par["gravityAccelerationY"],
                       par["gravityAccelerationZ"]]
        infos = [pb.getJointInfo(body_id, j, **kw) for j in range(n_links)]
        types = [int(ji[2]) for ji in infos]
        for j, t in enumerate(types):
            if t not in (_PB_REVOLUTE, _PB_PRISMATIC, _PB_SPHERICAL, _PB_FIXED):
                raise ValueError(f"joint {j} of {name}: unsupported PyBullet joint type {t}")
        base = pb.getDynamicsInfo(body_id, -1, **kw)
        if floating is None:
            floating = _is_floating(pb, client, body_id, types, float(base[0]))

        pos, orn = pb.getBasePositionAndOrientation(body_id, **kw)
        parent = [-1]
        jtype = [JT_FREE if floating else JT_FIXED_BASE]
        axis = [np.zeros(3)]
        tree_R = [np.eye(3) if floating else _quat_rot(orn)]
        tree_p = [np.zeros(3) if floating else np.array(pos, dtype=float)]
        mass = [float(base[0])]
        com = [np.zeros(3)]
        I_com = [np.diag(base[2]).astype(float)]
        body_names = [pb.getBodyInfo(body_id, **kw)[0].decode()]
        # PyBullet (btMultiBody) link frames are the inertial (COM, principal-axes) frames;
        # parentFramePos/Orn place the joint pivot and (inverted) the child's COM-frame
        # orientation at q = 0 in the parent's COM frame, and joint axes / spherical rotations
        # act in the child's COM axes. A body frame here sits at the joint pivot with the
        # COM-frame orientation, so the body's centre of mass is at d = R_in^T localInertialPos
        # (the URDF link origin is the pivot).
        # frames[j]: pose of link j's COM frame in its body frame; link -1 = the base.
        frames: dict[int, tuple[np.ndarray, np.ndarray]] = {-1: (np.eye(3), np.zeros(3))}
        body_of: dict[int, int] = {-1: 0}
        joint_indices = []
        for j, ji in enumerate(infos):
            di = pb.getDynamicsInfo(body_id, j, **kw)
            par = int(ji[16])
            pbody = body_of[par]
            R_pc, p_pc = frames[par]
            # joint frame (pivot, child COM orientation at q = 0) in the parent body frame.
            # NB: PyBullet reports parentFrameOrn as the *inverse* of that rotation (checked
            # against getLinkState; invisible for the identity and pi rotations of most URDFs).
            R_j = R_pc @ _quat_rot(ji[15]).T
            p_j = p_pc + R_pc @ np.asarray(ji[14], dtype=float)
            d = _quat_rot(di[4]).T @ np.asarray(di[3], dtype=float)  # pivot -> COM, COM axes
            m = float(di[0])
            I_c = np.diag(np.asarray(di[2], dtype=float))  # principal axes
            if types[j] == _PB_FIXED:
                # merge into the parent body: the link's COM frame in the parent body frame
                p_c = p_j + R_j @ d
                body_of[j] = pbody
                frames[j] = (R_j, p_c)
                M0, c0, I0 = mass[pbody], com[pbody], I_com[pbody]
                Mt = M0 + m
                ct = (M0 * c0 + m * p_c) / Mt if Mt > 0 else c0
                I_com[pbody] = (_shift_inertia(I0, M0, c0 - ct)
                                + _shift_inertia(R_j @ I_c @ R_j.T, m, p_c - ct))
                mass[pbody], com[pbody] = Mt, ct
                continue
            body_of[j] = len(parent)
            frames[j] = (np.eye(3), d)
            parent.append(pbody)
            jtype.append({_PB_REVOLUTE: JT_REVOLUTE, _PB_PRISMATIC: JT_PRISMATIC,
                          _PB_SPHERICAL: JT_SPHERICAL}[types[j]])
            ax = np.asarray(ji[13], dtype=float)
            if types[j] != _PB_SPHERICAL and abs(np.linalg.norm(ax) - 1.0) > 1e-6:
                raise ValueError(f"joint {j} of {name}: axis {tuple(ax)} is not a unit vector; "
                                 "PyBullet does not normalise URDF axes (its dynamics then differ "
                                 "from a rotation about the axis), so normalise it in the URDF")
            axis.append(ax)
            tree_R.append(R_j)
            tree_p.append(p_j)
            mass.append(m)
            com.append(d)
            I_com.append(I_c)
            body_names.append(ji[12].decode())
            joint_indices.append(j)
        link_body = np.array([body_of[j] for j in range(n_links)], dtype=np.int64)
        link_R = np.array([frames[j][0] for j in range(n_links)]).reshape(n_links, 3, 3)
        link_p = np.array([frames[j][1] for j in range(n_links)]).reshape(n_links, 3)
        return cls(name=name, floating=floating, parent=np.array(parent, dtype=np.int64),
                   jtype=np.array(jtype, dtype=np.int64), axis=np.array(axis),
                   tree_R=np.array(tree_R), tree_p=np.array(tree_p), mass=np.array(mass),
                   com=np.array(com), I_com=np.array(I_com),
                   gravity=np.asarray(gravity, dtype=float),
                   joint_indices=np.array(joint_indices, dtype=np.int64), link_body=link_body,
                   link_R=link_R, link_p=link_p, body_names=body_names)

    def set_base_pose(self, position: Any, orientation: Any) -> None:
        """World pose of a fixed base (position ``(3,)``, quaternion ``x, y, z, w``)."""
        if self.floating:
            raise ValueError("set_base_pose is for fixed-base models; a floating base pose is in q")
        self.tree_R[0] = _quat_rot(orientation)
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


def _is_floating(pb: Any, client: int, body_id: int, types: list[int], base_mass: float) -> bool:
    """Whether PyBullet simulates the base with 6 DoF (its mass-matrix size tells).

    PyBullet caches its inverse-dynamics tree per multibody pointer; after ``removeBody`` a new
    body can hit a stale tree and ``calculateMassMatrix`` fails. Then fall back to the URDF rule
    (a base of mass 0 is fixed), which is wrong only for ``useFixedBase=True`` with a massive base.
    """
    n_joint_q = sum(1 for t in types if t in (_PB_REVOLUTE, _PB_PRISMATIC)) + \
        4 * sum(1 for t in types if t == _PB_SPHERICAL)
    n_joint_v = sum(1 for t in types if t in (_PB_REVOLUTE, _PB_PRISMATIC)) + \
        3 * sum(1 for t in types if t == _PB_SPHERICAL)
    q0 = [0.0] * n_joint_q
    try:
        M = pb.calculateMassMatrix(body_id, q0, physicsClientId=client)
    except Exception:  # noqa: BLE001 - pybullet raises SystemError/pybullet.error
        return base_mass > 0.0
    return len(M) == n_joint_v + 6


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
