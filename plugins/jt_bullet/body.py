"""Lean state/torque exchange with a PyBullet body in ``toolkit.dynamics`` coordinates.

``BulletBody`` reads ``(q, qd)`` with one batched ``getJointStatesMultiDof`` call, writes
generalised forces with one ``setJointMotorControlMultiDofArray`` call (root forces, if any, as
an external world force at the base's centre of mass and a world torque), and drives PyBullet's
own C++ Stable PD (``STABLE_PD_CONTROL``, which acts inside the next ``stepSimulation``) or its
constraint motors (``POSITION_CONTROL``, ``spd=servo``).

PyBullet limits: its shared-memory API carries at most ``MAX_DEGREE_OF_FREEDOM = 128`` position
coordinates per body. Beyond that (e.g. the 195-DoF snake, ``n_q = 259``) joint states read back
empty and joint resets/motor commands corrupt the state, so ``BulletBody`` refuses such bodies.
"""

from __future__ import annotations

import math


import numpy as np

from toolkit.dynamics.model import Model

PYBULLET_MAX_Q = 128  #: MAX_DEGREE_OF_FREEDOM in PyBullet's SharedMemoryPublic.h


class BulletBody:
    """A PyBullet body viewed through a ``Model``'s generalised coordinates.

    Args:
        client: PyBullet physics client id.
        body_id: body unique id.
        model: its ``Model`` (``jt_bullet.model.model_from_bullet``).

    Raises:
        ValueError: if the body has more position coordinates than PyBullet's API can carry.
    """

    def __init__(self, client: int, body_id: int, model: Model) -> None:
        import pybullet

        if model.n_q > PYBULLET_MAX_Q:
            raise ValueError(
                f"{model.name}: {model.n_q} position coordinates exceed PyBullet's "
                f"MAX_DEGREE_OF_FREEDOM={PYBULLET_MAX_Q}; its joint-state API cannot read or "
                "drive this body")
        self.pb = pybullet
        self.client = client
        self.body = body_id
        self.model = model
        self.joints = [int(j) for j in model.joint_indices]
        self.nv_j = [int(n) for n in model.nv[1:]]
        self.nq_j = [int(n) for n in model.joint_nq]
        self.floating = model.floating
        self.base_dofs = 6 if model.floating else 0
        self.q = np.zeros(model.n_q)
        self.qd = np.zeros(model.n_v)
        self._kw = {"physicsClientId": client}
        self._vslices = []
        k = self.base_dofs
        for n in self.nv_j:
            self._vslices.append((k, k + n))
            k += n

    # ---------------------------------------------------------------------------------------
    def read(self) -> tuple[np.ndarray, np.ndarray]:
        """Current ``(q, qd)`` into (and returning) the preallocated ``self.q``, ``self.qd``."""
        pb, b, kw = self.pb, self.body, self._kw
        states = pb.getJointStatesMultiDof(b, self.joints, **kw)
        if self.floating:
            pos, orn = pb.getBasePositionAndOrientation(b, **kw)
            lin, ang = pb.getBaseVelocity(b, **kw)
            qs = [*pos, *orn, *[x for s in states for x in s[0]]]
            vs = [*lin, *ang, *[x for s in states for x in s[1]]]
        else:
            qs = [x for s in states for x in s[0]]
            vs = [x for s in states for x in s[1]]
        self.q[:] = qs
        self.qd[:] = vs
        # what the simulator's NaN / explosion check needs, from the Python floats (cheaper than
        # numpy reductions on arrays this small)
        self.speed_max = max(map(abs, vs)) if vs else 0.0
        self.finite = math.isfinite(sum(qs) + sum(vs))
        return self.q, self.qd

    def reset(self, q: np.ndarray, qd: np.ndarray) -> None:
        """Put the body in state ``(q, qd)``."""
        pb, b, kw = self.pb, self.body, self._kw
        q = np.asarray(q, dtype=float)
        qd = np.asarray(qd, dtype=float)
        kq = kv = 0
        if self.floating:
            pb.resetBasePositionAndOrientation(b, q[0:3].tolist(), q[3:7].tolist(), **kw)
            pb.resetBaseVelocity(b, qd[0:3].tolist(), qd[3:6].tolist(), **kw)
            kq, kv = 7, 6
        for j, nq, nv in zip(self.joints, self.nq_j, self.nv_j):
            pb.resetJointStateMultiDof(b, j, q[kq:kq + nq].tolist(), qd[kv:kv + nv].tolist(), **kw)
            kq += nq
            kv += nv

    def write_torques(self, tau: np.ndarray) -> bool:
        """Apply generalised forces ``(n_v,)`` for the next ``stepSimulation``; False (nothing
        applied) when one of them is NaN or infinite."""
        pb, b, kw = self.pb, self.body, self._kw
        t = tau.tolist()
        if not math.isfinite(sum(t)):
            return False
        forces = [t[a:e] for a, e in self._vslices]
        pb.setJointMotorControlMultiDofArray(b, self.joints, pb.TORQUE_CONTROL, forces=forces, **kw)
        if self.floating and any(t[0:6]):
            pos, _ = pb.getBasePositionAndOrientation(b, **kw)
            pb.applyExternalForce(b, -1, t[0:3], pos, pb.WORLD_FRAME, **kw)
            pb.applyExternalTorque(b, -1, t[3:6], pb.WORLD_FRAME, **kw)
        return True

    def _per_joint(self, q_target: np.ndarray, torque_limit: np.ndarray,
                   qd_target: np.ndarray | None) -> tuple[list, list, list, list[int]]:
        """Target positions, target velocities and force limits as PyBullet's per-joint lists, and
        each joint's first DoF index (in the ``qd`` layout)."""
        qt = np.asarray(q_target, dtype=float).tolist()
        vt = (np.zeros(self.model.n_v) if qd_target is None
              else np.asarray(qd_target, dtype=float)).tolist()
        lim = np.asarray(torque_limit, dtype=float).tolist()
        kq = 7 if self.floating else 0
        tp, tv, fl, first = [], [], [], []
        for (a, e), nq in zip(self._vslices, self.nq_j):
            tp.append(qt[kq:kq + nq])
            tv.append(vt[a:e])
            fl.append(lim[a:e])
            first.append(a)
            kq += nq
        return tp, tv, fl, first

    def stable_pd(self, q_target: np.ndarray, kp: np.ndarray, kd: np.ndarray,
                  torque_limit: np.ndarray, qd_target: np.ndarray | None = None) -> None:
        """Arm PyBullet's C++ Stable PD for the next ``stepSimulation`` (root unactuated).

        PyBullet takes one gain per joint: the gain of each joint's first DoF is used.
        """
        tp, tv, fl, first = self._per_joint(q_target, torque_limit, qd_target)
        self.pb.setJointMotorControlMultiDofArray(
            self.body, self.joints, self.pb.STABLE_PD_CONTROL, targetPositions=tp, targetVelocities=tv,
            forces=fl, positionGains=[float(kp[a]) for a in first], velocityGains=[float(kd[a]) for a in first],
            **self._kw)

    def servo(self, q_target: np.ndarray, torque_limit: np.ndarray, qd_target: np.ndarray | None = None,
              position_gain: float = 0.3, velocity_gain: float = 1.0) -> None:
        """Arm PyBullet's constraint motors (``POSITION_CONTROL``) towards ``q_target``; they stay
        armed through every later ``stepSimulation`` until re-armed (root unactuated).

        Each joint is a velocity constraint, solved with the contacts, driving the joint by
        ``position_gain`` of its position error per step (plus ``velocity_gain`` of its velocity
        error) with at most ``torque_limit`` per DoF: a stiff servo bounded by the torque limits.
        """
        tp, tv, fl, _ = self._per_joint(q_target, torque_limit, qd_target)
        n = len(self.joints)
        self.pb.setJointMotorControlMultiDofArray(
            self.body, self.joints, self.pb.POSITION_CONTROL, targetPositions=tp, targetVelocities=tv,
            forces=fl, positionGains=[float(position_gain)] * n, velocityGains=[float(velocity_gain)] * n,
            **self._kw)

    def step(self) -> None:
        """One ``stepSimulation``."""
        self.pb.stepSimulation(**self._kw)
