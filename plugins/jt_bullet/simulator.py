"""``sim=bullet``: one SPD-controlled character in a PyBullet world (y-up, ground plane).

Per control step (``control_hz``) the simulator runs ``sim_hz / control_hz`` substeps; in each,
the configured SPD backend (``cfg.spd``) computes torques towards the control step's target from
the current state, the torques are clipped to the character's limits (after the solve, as
DeepMimic and PyBullet do) and applied, and PyBullet steps once. A backend with
``steps_itself`` (``spd=bullet``, PyBullet's own STABLE_PD) is armed instead and acts inside the
step. A hand-of-God root servo (``sim.root_servo``, thesis ``001`` §2.4.1) puts SPD gains on the
6 root DoFs; our backends solve it jointly with the internal joints.

A NaN or exploding state ends the episode as a failure with a reason (later steps return the
same failed record without simulating); ``step`` never raises for it.

Timers: ``timers["spd_s"]`` accumulates the wall time of the SPD solves alone, ``physics_s`` that
of PyBullet's ``stepSimulation``, ``io_s`` state reads and torque writes (with the clip),
``substep_s`` that of whole substeps (solve, clip, apply, step, read), ``loop_s`` whole control
steps' substep loops (with the NaN checks and the ``Watch``), and ``substeps`` their count;
``spd_share`` is the thesis' Table 2.3 ratio. Setting
``step_log`` to a list makes every substep append ``(spd_s, substep_s)`` to it (for medians).
"""

from __future__ import annotations

import math
import time
from typing import Any, ClassVar

import numpy as np

from jt_bullet import watch as watcher
from jt_bullet.config import DEFAULT_CAMERA, CharacterConfig, SimConfig, typed
from jt_bullet.queries import SceneQueries
from toolkit.interfaces import Simulator
from toolkit.interfaces.simulator import Watch


def _get(cfg: Any, key: str) -> Any:
    if cfg is None:
        return None
    if isinstance(cfg, dict):
        return cfg.get(key)
    return cfg.get(key) if hasattr(cfg, "get") else getattr(cfg, key, None)


class BulletSimulator(SceneQueries, Simulator):
    """PyBullet world (y-up, ground) with one character driven by an SPD backend per substep."""

    Config: ClassVar[type] = SimConfig
    group_schemas: ClassVar[dict[str, type]] = {"character": CharacterConfig}
    native_modules: ClassVar[tuple[str, ...]] = ("pybullet",)  #: its build banner, silenced by toolkit.quiet

    def __init__(self, cfg: Any) -> None:
        import pybullet as pb

        from toolkit import plugins
        from jt_bullet.body import PYBULLET_MAX_Q, BulletBody
        from toolkit.errors import JtError
        from jt_bullet import scene

        super().__init__(cfg)
        self._scene_planes: tuple | None = None  # (n_bodies, ground ids or None), SceneQueries.ray
        self.params: SimConfig = typed(SimConfig, _get(cfg, "sim"), "sim")
        self.char_cfg = CharacterConfig.from_node(_get(cfg, "character"))
        p = self.params
        if not (p.sim_hz > 0 and p.control_hz > 0):
            raise JtError(f"sim: sim_hz and control_hz must be positive, got {p.sim_hz}, "
                          f"{p.control_hz}")
        ratio = p.sim_hz / p.control_hz
        if abs(ratio - round(ratio)) > 1e-6 or round(ratio) < 1:
            raise JtError(f"sim: sim_hz / control_hz must be a whole number >= 1, got "
                          f"{p.sim_hz} / {p.control_hz} = {ratio:g}")
        self.n_substeps = int(round(ratio))
        self._explode_d2 = float(p.explode_distance) ** 2
        self.dt = 1.0 / p.sim_hz
        spd_node = _get(cfg, "spd")
        spd_name = str(_get(spd_node, "name") or "maba")
        self.spd_name = spd_name
        self.backend = plugins.load("spd", spd_name)(spd_node)
        self.steps_itself = bool(getattr(self.backend, "steps_itself", False))
        if self.steps_itself and p.root_servo.kp != 0.0:
            raise JtError(f"spd={spd_name} cannot drive a root servo (PyBullet's STABLE_PD leaves "
                          "the root unactuated); use spd=maba/df/sf/pcg or sim.root_servo.kp=0")

        self.client, self.ground = scene.connect(self.dt, p.gravity, p.ground, p.friction,
                                                    p.solver_iterations)
        self._kw = {"physicsClientId": self.client}
        self._pb = pb
        kw = {} if p.self_collision is None else {"self_collision": bool(p.self_collision)}
        self.character = self.load_character(self.char_cfg, self.client, **kw)
        body = self.character.body_id
        scene.set_friction(self.client, body, p.friction)
        self.model = self.character.model()
        if self.model.n_q > PYBULLET_MAX_Q:
            self.close()
            raise JtError(f"character={self.char_cfg.name}: {self.model.n_q} position coordinates "
                          f"exceed PyBullet's limit of {PYBULLET_MAX_Q} per body; it cannot be "
                          "simulated (docs/maba.md)")
        self.io = BulletBody(self.client, body, self.model)
        self.backend.bind(self.io if self.steps_itself else self.model)
        self.n_links = pb.getNumJoints(body, **self._kw)
        self._masses = np.array([pb.getDynamicsInfo(body, i, **self._kw)[0] for i in range(-1, self.n_links)])
        self._link_ids = list(range(self.n_links))

        self.kp = np.array(self.character.kp, dtype=float)
        self.kd = np.array(self.character.kd, dtype=float)
        limit = np.array(self.character.torque_limit, dtype=float)
        if not p.torque_limits:
            limit[:] = np.inf
        if not self.character.fixed_base:
            self.kp[:6] = p.root_servo.kp
            self.kd[:6] = p.root_servo.kd
            limit[:6] = np.inf if p.root_servo.kp or p.root_servo.kd else 0.0
        self.torque_limit = limit
        self._neg_limit = -limit
        self._tau = np.zeros(self.model.n_v)
        self.time = 0.0
        self.failed = False
        self.reason = ""
        self.timers = {"spd_s": 0.0, "substep_s": 0.0, "physics_s": 0.0, "io_s": 0.0, "loop_s": 0.0, "substeps": 0}
        self.step_log: list | None = None
        self._last: dict[str, Any] = {}
        self._compiled: Any = None  # jt_bullet.compiled.CompiledSteps, False: the Python loop
        self._state_read = False  # io.q, io.qd hold the current state (the compiled loop's last read)
        if p.loop not in ("auto", "compiled", "python"):
            self.close()
            raise JtError(f"sim.loop={p.loop!r}: choose auto, compiled or python")
        if p.loop != "python":
            from jt_bullet import compiled

            why = compiled.unavailable(self)
            if why and p.loop == "compiled":
                self.close()
                raise JtError(f"sim.loop=compiled: not available here: {why}; use sim.loop=auto or python")
            self._compiled = False if why else compiled.CompiledSteps(self)
        else:
            self._compiled = False

    @property
    def loop(self) -> str:
        """``"compiled"`` or ``"python"``: the substep loop this simulator runs."""
        return "compiled" if self._compiled else "python"

    # ------------------------------------------------------------------ characters
    @classmethod
    def check_run(cls, cfg: Any) -> None:
        """Per-joint overrides (``character.joint_kp`` / ``joint_kd`` / ``joint_torque_limit``) name
        joints the character has: checked at composition by loading it once in a private DIRECT
        client (~0.2 s, only when such a table is given), one line listing the joints otherwise.
        And a root servo (``sim.root_servo.kp`` > 0) needs a backend whose torques it can add to."""
        from toolkit import plugins
        from toolkit.errors import JtError

        spd_name = str(_get(_get(cfg, "spd"), "name") or "maba")
        servo = _get(_get(cfg, "sim"), "root_servo")
        if float(_get(servo, "kp") or 0.0) != 0.0 and getattr(plugins.load("spd", spd_name), "steps_itself", False):
            able = [n for n in plugins.names("spd") if not getattr(plugins.load("spd", n), "steps_itself", False)]
            raise JtError(f"spd={spd_name} cannot drive a root servo (it computes its torques inside the step and "
                          f"leaves the root unactuated); use spd={'/'.join(able)} or sim.root_servo.kp=0")
        cc = CharacterConfig.from_node(_get(cfg, "character"))
        if not (cc.joint_kp or cc.joint_kd or cc.joint_torque_limit):
            return
        from toolkit.quiet import native_stderr_silenced

        with native_stderr_silenced():  # PyBullet's import banner, printed from C
            import pybullet as pb

            client = pb.connect(pb.DIRECT)
        try:
            cls.load_character(cc, client)
        finally:
            pb.disconnect(client)

    # ------------------------------------------------------------------ kinematics (no world)
    @classmethod
    def forward_kinematics(cls, skeleton: Any, root_pos: np.ndarray, root_rot: np.ndarray,
                           joints: np.ndarray) -> Any:
        """Link poses of mocap poses by PyBullet (``jt_bullet.kinematics.forward_kinematics``)."""
        from jt_bullet.kinematics import forward_kinematics

        return forward_kinematics(skeleton, root_pos, root_rot, joints)

    @classmethod
    def kinematic_body(cls, skeleton: Any) -> Any:
        """A never-stepped copy of the skeleton's character (``jt_bullet.kinematics.KinematicBody``)."""
        from jt_bullet.kinematics import KinematicBody

        return KinematicBody(skeleton)

    @classmethod
    def render_poses(cls, skeleton: Any, dofs: np.ndarray, **kw: Any) -> list:
        """Still poses ``(n, n_dof)`` by TinyRenderer (``jt_bullet.render.render_poses``)."""
        from jt_bullet.render import render_poses

        return render_poses(skeleton, dofs, **kw)

    @classmethod
    def spd_bench(cls) -> Any:
        """The SPD benchmark of this simulator's characters (``jt bench spd``): the module
        ``jt_bullet.bench`` (``time_spd``, ``check_agreement``, ``summarize``)."""
        from jt_bullet import bench

        return bench

    @classmethod
    def load_character(cls, name: Any, client: Any, **kw: Any) -> Any:
        """Load a character into ``client`` with a ``CharacterConfig``'s gain overrides applied
        (``jt_bullet.characters.load_configured``), for tools (``jt bench spd``) that need the
        built-in characters without a simulator."""
        from jt_bullet.characters import load_configured

        return load_configured(name, client, **kw)

    # ------------------------------------------------------------------ Simulator API
    @property
    def sim_hz(self) -> float:
        """``sim.sim_hz`` (Hz)."""
        return float(self.params.sim_hz)

    @property
    def control_hz(self) -> float:
        """``sim.control_hz`` (Hz)."""
        return float(self.params.control_hz)

    @property
    def friction(self) -> float:
        """``sim.friction``: the ground's and the character's lateral friction."""
        return float(self.params.friction)

    def reset(self, q: np.ndarray, qd: np.ndarray) -> None:
        """Put the character in state ``(q, qd)`` (``toolkit.dynamics`` layout); time = 0."""
        self.io.reset(np.asarray(q, dtype=float), np.asarray(qd, dtype=float))
        self.time = 0.0
        self.failed = False
        self.reason = ""
        self._tau[:] = 0.0
        self._last = {}
        self._state_read = False  # PyBullet may store q differently (a normalised quaternion): read it

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        """Current ``(q (n_q,), qd (n_dof,))`` (copies). With the compiled loop, the state its last
        substep read (or the last read since a reset) is the current one: no second C API request."""
        if self._compiled:
            if not self._state_read:
                self._compiled.read()
                self._state_read = True
            q, qd = self.io.q, self.io.qd
        else:
            q, qd = self.io.read()
        return q.copy(), qd.copy()

    def step(self, q_target: np.ndarray, qd_target: np.ndarray | None = None,
             n_substeps: int | None = None, watch: Watch | None = None) -> dict[str, Any]:
        """One control step: ``n_substeps`` (default ``self.n_substeps``) SPD-controlled substeps
        towards ``q_target``, ``watch``'s rules checked inside the loop.

        Every substep reads the state, solves SPD, clips and applies the torques and steps
        PyBullet, then checks the new state for NaN / explosion (a failure stops the loop); every
        ``watch.check_every``-th substep (and the last) evaluates ``watch`` (``jt_bullet.watch``).

        Args:
            q_target: target positions ``(n_q,)``; the root part is read only with a root servo.
            qd_target: target velocities ``(n_dof,)``; zero if None.
            n_substeps: substeps of this control step (e.g. fewer at the end of an episode).
            watch: the termination rules and records of the episode (``toolkit.interfaces.Watch``).

        Returns:
            The step record: ``time`` (s), ``q`` ``(n_q,)``, ``qd`` ``(n_dof,)``, ``tau``
            ``(n_dof,)`` (last applied, clipped; NaN for ``spd=bullet``), ``failed``, ``reason``,
            ``substeps`` (simulated), ``outcome`` (``""``, ``"fail"``, ``"success"``,
            ``"truncate"``), ``touched`` ``{body: links}``, ``samples`` ``{name: (k, ...)}`` and,
            with ``sim.contacts``, ``contacts`` (bool ``(n_links + 1,)``, index = link + 1) and
            ``n_contacts``.
        """
        if self.failed:
            return dict(self._last, failed=True, reason=self.reason, substeps=0, outcome="fail",
                        touched={}, samples=watcher.empty_samples(watch))
        pb, kw, io, be = self._pb, self._kw, self.io, self.backend
        qt = np.ascontiguousarray(q_target, dtype=float)
        if qt.shape != (self.model.n_q,):
            raise ValueError(f"q_target has shape {qt.shape}, expected ({self.model.n_q},)")
        vt = None if qd_target is None else np.ascontiguousarray(qd_target, dtype=float)
        n = self.n_substeps if n_substeps is None else int(n_substeps)
        kp, kd, lim, dt, tau = self.kp, self.kd, self.torque_limit, self.dt, self._tau
        neg_lim = self._neg_limit
        if self._compiled and self.step_log is None:
            return self._step_compiled(qt, vt, n, watch)
        solve = getattr(be, "solve", be.torques)  # the backend's lean path when it has one
        check = watcher.Checker(self, watch, n)
        perf = time.perf_counter
        spd_s = sub_s = phys_s = io_s = 0.0
        done = 0
        t_start = perf()
        q, qd = io.read()
        for k in range(n):
            t0 = perf()
            if self.steps_itself:
                be.apply(qt, kp, kd, lim, vt)
                ts = 0.0
                t2 = perf()
            else:
                raw = solve(q, qd, qt, kp, kd, dt, vt)
                t1 = perf()
                ts = t1 - t0
                np.minimum(raw, lim, out=tau)
                np.maximum(tau, neg_lim, out=tau)
                if not io.write_torques(tau):
                    self._fail("non-finite SPD torques (NaN or exploding state)")
                    break
                t2 = perf()
                io_s += t2 - t1
            pb.stepSimulation(**kw)
            t3 = perf()
            q, qd = io.read()
            t4 = perf()
            phys_s += t3 - t2
            io_s += t4 - t3
            dt_sub = t4 - t0
            sub_s += dt_sub
            spd_s += ts
            done += 1
            self.time += dt
            if self.step_log is not None:
                self.step_log.append((ts, dt_sub))
            self._check(q, qd)
            if self.failed or check.after_substep(k, q):
                break
        tm = self.timers
        tm["spd_s"] += spd_s
        tm["substep_s"] += sub_s
        tm["physics_s"] += phys_s
        tm["io_s"] += io_s
        tm["loop_s"] += perf() - t_start
        tm["substeps"] += done
        return self._record(q, qd, tau, done, check.result(self.failed, self.reason))

    def _step_compiled(self, qt: np.ndarray, vt: np.ndarray | None, n: int,
                       watch: Watch | None) -> dict[str, Any]:
        """``step`` through ``jt_bullet.fastloop`` (the same record)."""
        from jt_bullet import fastloop as fl

        cs = self._compiled
        t_start = time.perf_counter()
        cs.timers[:] = 0.0
        done, result = cs.step(qt, vt, n, watch)
        self._state_read = True  # the loop read the state after its last substep into io.q, io.qd
        tm, ct = self.timers, cs.timers
        tm["spd_s"] += float(ct[fl.T_SPD])
        tm["substep_s"] += float(ct[fl.T_SUB])
        tm["physics_s"] += float(ct[fl.T_PHYS])
        tm["io_s"] += float(ct[fl.T_IO])
        tm["loop_s"] += time.perf_counter() - t_start
        tm["substeps"] += done
        return self._record(self.io.q, self.io.qd, self._tau, done, result)

    def _record(self, q: np.ndarray, qd: np.ndarray, tau: np.ndarray, done: int,
                result: dict[str, Any]) -> dict[str, Any]:
        """The step record (``step``'s Returns) of a finished control step."""
        rec = {"time": self.time, "q": q.copy(), "qd": qd.copy(),
               "tau": np.full(self.model.n_v, np.nan) if self.steps_itself else tau.copy()}
        if self.params.contacts:
            touching, n_pts = self._contacts()
        else:
            touching, n_pts = np.zeros(self.n_links + 1, dtype=bool), 0
        rec.update(contacts=touching, n_contacts=n_pts, failed=self.failed, substeps=done, **result)
        self._last = rec
        return rec

    def close(self) -> None:
        """Disconnect the PyBullet client (idempotent)."""
        if getattr(self, "client", None) is not None:
            try:
                self._pb.disconnect(**self._kw)
            except Exception:  # noqa: BLE001 - already disconnected
                pass
            self.client = None

    def __del__(self) -> None:  # pragma: no cover - best effort
        try:
            self.close()
        except Exception:  # noqa: BLE001
            pass

    # ------------------------------------------------------------------ helpers
    @property
    def spd_share(self) -> float:
        """SPD solve time over whole-substep time so far (NaN for ``spd=bullet`` or no steps)."""
        if self.steps_itself or self.timers["substep_s"] <= 0.0:
            return math.nan
        return self.timers["spd_s"] / self.timers["substep_s"]

    def reset_timers(self) -> None:
        """Zero the SPD / substep timers."""
        self.timers = {"spd_s": 0.0, "substep_s": 0.0, "physics_s": 0.0, "io_s": 0.0, "loop_s": 0.0, "substeps": 0}

    def _check(self, q: np.ndarray, qd: np.ndarray) -> None:
        """NaN / exploding state → failure. Runs after every substep on the state ``io.read``
        just returned, with the maximum speed and finiteness it computed alongside."""
        p, io = self.params, self.io
        vmax = io.speed_max
        if io.finite and vmax <= p.explode_speed and (
                self.character.fixed_base or q[0] * q[0] + q[1] * q[1] + q[2] * q[2] <= self._explode_d2):
            return
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(qd))):
            self._fail("NaN state")
        elif vmax > p.explode_speed:
            self._fail(f"exploded: |qd| = {vmax:.3g} > explode_speed = {p.explode_speed:g}")
        else:
            self._fail(f"exploded: root {float(np.linalg.norm(q[:3])):.3g} m from the origin")

    def _fail(self, reason: str) -> None:
        self.failed = True
        self.reason = reason

    def _contacts(self) -> tuple[np.ndarray, int]:
        from jt_bullet.scene import contact_summary

        return contact_summary(self.client, self.character.body_id, self.n_links)
