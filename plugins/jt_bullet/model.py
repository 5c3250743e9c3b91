"""The ``toolkit.dynamics.Model`` of a PyBullet body: topology, frames, masses and inertias.

The simulator plugin builds the model of every body it drives here (``Character.model``, the
planar worlds, ``BulletSimulator``); ``toolkit.dynamics`` itself reads no simulator. The
coordinate conventions (PyBullet's, ``toolkit.dynamics.model``) are checked against PyBullet by the
dynamics tests: one ``stepSimulation`` reproduces ``qd + dt * aba(q, qd, tau)`` to ~1e-12.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from toolkit.dynamics.model import (JT_FIXED_BASE, JT_FREE, JT_PRISMATIC, JT_REVOLUTE,
                                    JT_SPHERICAL, Model, quat_matrix, shift_inertia)

#: PyBullet's joint types (``getJointInfo``'s third entry)
_PB_REVOLUTE, _PB_PRISMATIC, _PB_SPHERICAL, _PB_FIXED = 0, 1, 2, 4


def model_from_bullet(client: int, body_id: int, name: str | None = None, gravity: Any = None,
                      floating: bool | None = None) -> Model:
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
    tree_R = [np.eye(3) if floating else quat_matrix(orn)]
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
        R_j = R_pc @ quat_matrix(ji[15]).T
        p_j = p_pc + R_pc @ np.asarray(ji[14], dtype=float)
        d = quat_matrix(di[4]).T @ np.asarray(di[3], dtype=float)  # pivot -> COM, COM axes
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
            I_com[pbody] = (shift_inertia(I0, M0, c0 - ct)
                            + shift_inertia(R_j @ I_c @ R_j.T, m, p_c - ct))
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
    return Model(name=name, floating=floating, parent=np.array(parent, dtype=np.int64),
                 jtype=np.array(jtype, dtype=np.int64), axis=np.array(axis),
                 tree_R=np.array(tree_R), tree_p=np.array(tree_p), mass=np.array(mass),
                 com=np.array(com), I_com=np.array(I_com),
                 gravity=np.asarray(gravity, dtype=float),
                 joint_indices=np.array(joint_indices, dtype=np.int64), link_body=link_body,
                 link_R=link_R, link_p=link_p, body_names=body_names)


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
