"""``BulletSimulator.step`` through the compiled substep loop (``jt_bullet.fastloop``).

``CompiledSteps`` packs what the loop needs once per simulator (the model's tables, the
PyBullet-to-jt state maps, the SPD kernel and its workspaces, buffers) and each ``Watch`` into
arrays, grouped in the tuples ``fastloop.substeps`` takes, runs a control step's substeps in one call and turns the result into the simulator's step
record, the same one the Python loop builds. ``CompiledSteps.unavailable(sim)`` says why a
simulator cannot use it (``sim.loop=python`` then, or the Python loop where ``sim.loop=auto``).
"""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from toolkit.interfaces.simulator import Watch

_KERNELS = {"maba": -1, "df": 0, "sf": 1, "pcg": 2, "servo": 3}
_CHECKER_REASONS = {1: "NaN state", 4: "non-finite SPD torques (NaN or exploding state)"}


def unavailable(sim: Any) -> str:
    """Why ``sim`` (a ``BulletSimulator``) cannot step through the compiled loop; "" if it can."""
    from toolkit.render import window_requested

    if window_requested():  # a GUI client (jt play --gui) steps through PyBullet's own API
        return "a window was asked for (the compiled loop drives DIRECT clients)"
    be = sim.backend
    servo = getattr(be, "method", None) == "servo"  # motors armed once per control step, no kernel
    if sim.steps_itself and not servo:
        return f"spd={sim.spd_name} steps inside PyBullet itself"
    if getattr(be, "method", None) not in _KERNELS or not (servo or hasattr(be, "data")):
        return f"the SPD backend {type(be).__name__} has no toolkit.dynamics kernel"
    if not sim.character.fixed_base and np.any(sim.torque_limit[:6] != 0.0):
        return "a root servo (its forces go through applyExternalForce)"
    from jt_bullet import capi

    _h, why = capi.handle(sim.client, sim.character.body_id)
    return why


class CompiledSteps:
    """The compiled loop bound to one ``BulletSimulator``.

    Args:
        sim: the simulator (its client, character, model, backend, gains and limits).
    """

    def __init__(self, sim: Any) -> None:
        import pybullet as pb

        from jt_bullet import capi, fastloop
        from toolkit.dynamics.com import CenterOfMass

        self.sim = sim
        self.fl = fastloop
        self.fns = fastloop.funcs()
        self.h, why = capi.handle(sim.client, sim.character.body_id)
        if not self.h:
            raise RuntimeError(why)
        self.ok_contact = capi.CMD_CONTACT_POINT_INFORMATION_COMPLETED
        m, be, body, kw = sim.model, sim.backend, sim.character.body_id, {"physicsClientId": sim.client}
        self.body = int(body)
        qmap, umap, j_uindex, j_start, j_count = [], [], [], [], []
        if m.floating:
            qmap, umap = list(range(7)), list(range(6))
        k = 6 if m.floating else 0
        for j, nq, nv in zip(m.joint_indices, m.joint_nq, m.nv[1:]):
            info = pb.getJointInfo(body, int(j), **kw)
            qmap += [info[3] + i for i in range(int(nq))]
            umap += [info[4] + i for i in range(int(nv))]
            j_uindex.append(info[4])
            j_start.append(k)
            j_count.append(int(nv))
            k += int(nv)
        i64 = np.int64
        self.qmap, self.umap = np.array(qmap, i64), np.array(umap, i64)
        self.j_uindex, self.j_start, self.j_count = (np.array(x, i64) for x in (j_uindex, j_start, j_count))
        self.bq = np.zeros(int(max(qmap) + 1) if qmap else 0)
        self.bu = np.zeros(int(max(umap) + 1) if umap else 0)
        self.holder = np.zeros(4, i64)
        self.ts = np.zeros(2, i64)
        self.cinfo = np.zeros(2, i64)
        self.cinfo32 = self.cinfo.view(np.int32)
        self.pts = np.zeros(capi.POINT_WORDS * 1024, np.int32)
        self.ls = np.zeros(fastloop.LINK_STATE_DOUBLES)
        self.method = _KERNELS[be.method]
        if self.method == fastloop.SERVO:  # no SPD kernel: scratch arrays of the loop's signature
            from toolkit.dynamics.model import Data

            self.data = Data(m)
            self.data.tau[:] = np.nan  # PyBullet reports no motor torques (as the Python loop)
        else:
            self.data = be.data
        self.tol = float(getattr(be, "tol", 1e-12))
        self.max_iter = int(getattr(be, "max_iter_factor", 20)) * m.n_v
        self.zeros = np.zeros(m.n_v)
        com = CenterOfMass(m)
        self.timers = np.zeros(4)
        self.iout = np.zeros(5, i64)
        self.fout = np.zeros(2)
        d = self.data  # ``fastloop.substeps``' groups that stay the same for the body's life
        self.api = (self.fns, self.h, self.body, self.ok_contact)
        self.maps = (self.qmap, self.umap, self.j_uindex, self.j_start, self.j_count)
        self.bufs = (self.bq, self.bu, self.holder, self.ts, self.cinfo, self.cinfo32, self.pts)
        self.spd = (self.method, m.mi, m.mf, m.dof_parent, m.gravity, d.wb, d.wv, d.sc, d.H, d.A,
                    self.zeros, self.tol, self.max_iter)
        self.com = (com._mass, com._com, com._world, com._wb, com._sc)
        self.out = (self.timers, self.iout, self.fout)
        self._watch: Optional[Watch] = None
        self._packed: tuple = ()
        self._n_links = sim.n_links

    def _pack(self, watch: Optional[Watch], n: int) -> tuple:
        """The rule, touch and record arrays of ``watch`` (cached for the last watch seen): ``(cap,
        watch, substeps' watch group, its records group, touch bodies, time rows, CoM rows, root
        rows)``, room for ``cap >= n`` records."""
        if watch is self._watch and self._packed and self._packed[0] >= n:
            return self._packed
        nl = self._n_links + 1
        w = watch if watch is not None else Watch()
        for key in w.record:
            if key not in ("time", "com", "root"):
                raise ValueError(f"Watch.record: unknown quantity {key!r}; choose from ['com', 'root', 'time']")
        nr = len(w.rules)
        mask = np.zeros((nr, nl), dtype=np.bool_)
        for r, rule in enumerate(w.rules):
            links = range(-1, nl - 1) if rule.links is None else rule.links
            for link in links:
                if -1 <= link < nl - 1 and link not in rule.except_links:
                    mask[r, link + 1] = True
        touches = np.array(w.touches, np.int64)
        active = bool(w.rules or w.touches or w.record or w.time_limit is not None)
        group = (max(1, int(w.check_every)), active, np.inf if w.time_limit is None else float(w.time_limit),
                 np.array([r.body for r in w.rules], np.int64), mask,
                 np.array([r.outcome == "fail" for r in w.rules], np.bool_),
                 np.array([-1 if r.clear_of is None else int(r.clear_of) for r in w.rules], np.int64),
                 np.array([float(r.margin) for r in w.rules]), touches)
        cap = max(n, 1)
        flags = np.array(["time" in w.record, "com" in w.record, "root" in w.record], np.bool_)
        rows = (np.zeros(cap), np.zeros((cap, 3)), np.zeros((cap, 7)))
        self._watch = watch
        self._packed = (cap, w, group, (flags, *rows), touches, *rows)
        return self._packed

    def read(self) -> tuple[np.ndarray, np.ndarray]:
        """The body's state into (and returning) ``sim.io.q`` ``(n_q,)``, ``sim.io.qd`` ``(n_v,)``,
        by the C API (PyBullet's ``getJointStatesMultiDof`` reads the same doubles)."""
        io = self.sim.io
        self.fl.read_state(self.fns, self.h, self.body, self.holder, self.bq, self.bu, self.qmap,
                           self.umap, io.q, io.qd)
        return io.q, io.qd

    def link_states(self) -> tuple[np.ndarray, np.ndarray]:
        """New arrays: centre-of-mass positions ``(n_links + 1, 3)`` and orientations
        ``(n_links + 1, 4)`` of the base and every link (``SceneQueries.link_states``)."""
        pos = np.empty((self._n_links + 1, 3))
        orn = np.empty((self._n_links + 1, 4))
        self.fl.link_states(self.fns, self.h, self.body, self.holder, self.ls, pos, orn)
        return pos, orn

    def link_velocities(self) -> tuple[np.ndarray, np.ndarray]:
        """New arrays: world linear and angular velocities ``(n_links + 1, 3)`` of the base and
        every link's centre of mass (``SceneQueries.link_velocities``)."""
        lin = np.empty((self._n_links + 1, 3))
        ang = np.empty((self._n_links + 1, 3))
        self.fl.link_velocities(self.fns, self.h, self.body, self.holder, self.ls, lin, ang)
        return lin, ang

    def link_frames(self, links: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """New arrays: URDF-frame positions ``(n, 3)`` and orientations ``(n, 4)`` of ``links``
        ``(n,)`` int64 (-1: the base), by forward kinematics (``SceneQueries.link_poses``)."""
        pos = np.empty((len(links), 3))
        orn = np.empty((len(links), 4))
        self.fl.link_frames(self.fns, self.h, self.body, self.holder, self.ls, links, pos, orn)
        return pos, orn

    def step(self, qt: np.ndarray, vt: Optional[np.ndarray], n: int,
             watch: Optional[Watch]) -> tuple[int, dict[str, Any]]:
        """Run ``n`` substeps towards ``qt``; ``(substeps done, the watch's result)`` with the
        simulator's time, failure, state (``sim.io.q``, ``sim.io.qd``) and torques updated."""
        sim, be = self.sim, self.sim.backend
        _cap, w, group, records, touches, r_time, r_com, r_root = self._pack(watch, n)
        touched = np.zeros((len(touches), self._n_links + 1), np.bool_)
        touched_any = np.zeros(len(touches), np.bool_)
        d = self.data
        io = sim.io
        if self.method == self.fl.SERVO:
            be.apply(qt, sim.kp, sim.kd, sim.torque_limit, vt)  # the motors hold it through the substeps
        self.fl.substeps(
            self.api, self.maps, self.bufs, self.spd, self.com, group, records, int(n), sim.time,
            (qt, self.zeros if vt is None else vt, sim.kp, sim.kd, sim.torque_limit, sim.dt),
            (float(sim.params.explode_speed), sim._explode_d2, bool(sim.character.fixed_base)),
            io.q, io.qd, touched, touched_any, self.out)
        done, fail, fired, n_rec, its = (int(x) for x in self.iout)
        sim.time = float(self.fout[0])
        if self.method == 2:
            d.iterations = its
        sim._tau[:] = d.tau
        io.speed_max = float(self.fout[1])
        if fail:
            if fail in _CHECKER_REASONS:
                sim._fail(_CHECKER_REASONS[fail])
            elif fail == 2:
                sim._fail(f"exploded: |qd| = {self.fout[1]:.3g} > explode_speed = {sim.params.explode_speed:g}")
            else:
                sim._fail(f"exploded: root {float(np.linalg.norm(io.q[:3])):.3g} m from the origin")
        samples = {}
        for key in w.record:
            src = {"time": r_time, "com": r_com, "root": r_root}[key]
            samples[key] = src[:n_rec].copy()
        touched_d = {int(b): tuple(int(i) - 1 for i in np.flatnonzero(touched[t]))
                     for t, b in enumerate(touches) if touched_any[t]}
        if fired >= 0:
            outcome, reason = w.rules[fired].outcome, w.rules[fired].reason
        elif fired == -2:
            outcome, reason = w.time_limit_outcome, w.time_limit_reason
        else:
            outcome, reason = "", ""
        if sim.failed:
            res = {"outcome": "fail", "reason": sim.reason, "touched": touched_d, "samples": samples}
        else:
            res = {"outcome": outcome, "reason": reason if outcome else sim.reason,
                   "touched": touched_d, "samples": samples}
        return done, res
