"""One standing jump in PyBullet: build the world, run the controller, measure the result.

PyBullet runs in its own DIRECT client per call (nothing shared between evaluations, so the same
parameters give the same result). The default joint motors are disabled and the controller's
torques are applied with ``TORQUE_CONTROL`` at every simulation step (``sim_hz``, 600 Hz by
default). The PD targets become torques by Stable PD, solved by one of jt's SPD backends
(``spd=maba|df|sf|pcg``, loaded through the plugin registry) on ``Model.from_bullet`` of the
body. The supernatural assist of ``004`` §3.3 is reduced gravity after take-off, ramping back
to -9.8 m/s² over the assist duration; it is applied with ``setGravity`` only while it differs
from normal gravity, so a natural controller runs with exactly zero external force.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Optional

from jt_tasks.standing_jump import params as P
from jt_tasks.standing_jump.controller import JumpController
from jt_tasks.standing_jump.kinematics import PlanarKinematics
from jt_tasks.standing_jump.timing import Timing
from jt_tasks.standing_jump.model import Body, build_body, effort_weights, standing_head_height, write_urdf


@dataclasses.dataclass
class SimSettings:
    """What a simulation needs besides the parameters (built from the task's Config).

    Attributes:
        sim_hz: simulation (and control) rate, Hz.
        mass: character mass, kg.
        height: character height, m.
        friction: ground and foot Coulomb friction coefficient.
        timing: phase timing and feedback gains.
        max_time: longest simulated time before the episode counts as failed (s).
        upright_fraction: at the end the head must be above this fraction of its standing height.
        landing_target: l_o, the landing position target relative to the start (m, ``004`` eq 3).
        landing_tolerance: l_r, the landing bracket half-width (m, ``004`` eq 3).
        assist_deadzone: assists below this many m/s² are no assist (exact natural case).
        stable_pd: Stable PD torques (implicit damping); False: explicit PD (unstable at 1 kHz with
            the default gains, kept for comparison).
        spd: the run's ``spd`` group as a plain dict (``{"name": "maba"}``: registry name of the
            SPD backend and its parameters); any of maba, df, sf, pcg (``bullet`` cannot serve:
            it never returns torques, and the controller adds torques after the solve).
    """

    sim_hz: float = 600.0
    mass: float = 80.0
    height: float = 1.60
    friction: float = 1.0
    timing: Timing = dataclasses.field(default_factory=Timing)
    max_time: float = 6.0
    upright_fraction: float = 0.8
    landing_target: float = 0.0
    landing_tolerance: float = 0.25
    assist_deadzone: float = 0.05
    stable_pd: bool = True
    spd: dict = dataclasses.field(default_factory=lambda: {"name": "maba"})


@dataclasses.dataclass
class JumpResult:
    """What one jump measured.

    Attributes:
        success: landed inside the box and stood up without falling.
        reason: why not ('' on success): 'fall', 'landing_outside_box', 'no_takeoff', 'no_landing',
            'not_upright', 'unstable'.
        height: apex height of the head's centre of mass while airborne (m); the standing head
            height when the character never left the ground.
        com_height: apex height of the whole-body CoM while airborne (m).
        e_je: weighted internal joint effort ``sum_t sum_i w_i tau_i^2 dt`` (N² m² s, ``004`` eq 4).
        e_se: external (supernatural) effort ``sum_t |F_ext|^2 dt`` (N² s, ``004`` eq 6).
        takeoff_gravity: gravity right after take-off (m/s²; -9.8 when natural).
        assist_time: duration of the gravity ramp (s; 0 when natural).
        landing_x: l_p, horizontal mid-foot displacement at touch-down from its start (m).
        flight_time: time from lift-off to touch-down (s).
        liftoff_velocity: vertical CoM velocity at lift-off (m/s; 0 without lift-off).
        liftoff_vx: horizontal CoM velocity at lift-off (m/s).
        liftoff_momentum: whole-body angular momentum about the CoM at lift-off (kg m²/s, + = forward).
        sim_time: simulated time (s).
        events: ``[(phase, time)]`` phase entries.
        snapshots: ``[(label, q)]`` joint positions at phase entries and the apex (when recorded).
    """

    success: bool
    reason: str
    height: float
    com_height: float
    e_je: float
    e_se: float
    takeoff_gravity: float
    assist_time: float
    landing_x: float
    flight_time: float
    sim_time: float
    liftoff_velocity: float = 0.0
    liftoff_vx: float = 0.0
    liftoff_momentum: float = 0.0
    events: list = dataclasses.field(default_factory=list)
    snapshots: list = dataclasses.field(default_factory=list)

    @property
    def natural(self) -> bool:
        """True when no external force was applied."""
        return self.e_se == 0.0


def open_world(body: Body, friction: float, sim_hz: float,
               rgba: tuple = (0.55, 0.36, 0.2, 1.0)) -> tuple[int, int, int, list[str]]:
    """A DIRECT PyBullet client with a ground plane and the character standing at x = 0.

    Returns:
        ``(client id, robot id, ground id, joint names)``; the caller disconnects.
    """
    import pybullet as p

    cid = p.connect(p.DIRECT)
    p.setGravity(0.0, 0.0, P.NATURAL_GRAVITY, physicsClientId=cid)
    p.setTimeStep(1.0 / sim_hz, physicsClientId=cid)
    shape = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=cid)
    visual = p.createVisualShape(p.GEOM_BOX, halfExtents=[20, 2, 0.005], rgbaColor=[0.85, 0.85, 0.8, 1],
                                 visualFramePosition=[0, 0, -0.005], physicsClientId=cid)
    ground = p.createMultiBody(0, shape, visual, physicsClientId=cid)
    robot = p.loadURDF(str(write_urdf(body, rgba)), useFixedBase=True, flags=p.URDF_USE_INERTIA_FROM_FILE,
                       physicsClientId=cid)
    n = p.getNumJoints(robot, physicsClientId=cid)
    names = [p.getJointInfo(robot, i, physicsClientId=cid)[1].decode() for i in range(n)]
    p.changeDynamics(ground, -1, lateralFriction=friction, restitution=0.0, physicsClientId=cid)
    for i in range(-1, n):
        p.changeDynamics(robot, i, lateralFriction=friction, restitution=0.0, linearDamping=0.0,
                         angularDamping=0.0, jointDamping=0.0, physicsClientId=cid)
    p.setJointMotorControlArray(robot, list(range(n)), p.VELOCITY_CONTROL, forces=[0.0] * n, physicsClientId=cid)
    p.resetJointState(robot, names.index("root_z"), body.hip_height + 1e-4, physicsClientId=cid)
    return cid, robot, ground, names


def simulate(point: dict[str, float], settings: Optional[SimSettings] = None, record: bool = False,
             record_every: float = 0.0, trace: Optional[list] = None) -> JumpResult:
    """Simulate one jump with the controller parameters ``point`` (names of ``params.space()``).

    Args:
        point: parameter values; missing ones take the seed controller's.
        settings: simulation settings (defaults if None).
        record: keep joint-position snapshots at phase entries and the apex (for filmstrips).
        record_every: instead keep a snapshot every this many seconds (0: at phase entries).
        trace: if a list, one ``(t, phase, com_x, com_z, com_vx, com_vz, pelvis pitch, chest pitch,
            angular momentum about the CoM)`` tuple per step is appended.
    """
    import pybullet as p

    st = settings or SimSettings()
    body = build_body(st.mass, st.height)
    g0, t_assist = P.assist(point, st.assist_deadzone)

    def gravity(t: float) -> float:
        if t_assist == 0.0 or t >= t_assist:
            return P.NATURAL_GRAVITY
        return g0 + (P.NATURAL_GRAVITY - g0) * (t / t_assist)

    ctrl = JumpController(body, P.phase_targets(point), st.timing, gravity)
    cid, robot, ground, names = open_world(body, st.friction, st.sim_hz)
    try:
        ep = _Episode(p, cid, robot, ground, names, body, ctrl, st)
        return ep.run(gravity, g0, t_assist, record, record_every, trace)
    finally:
        p.disconnect(cid)


def spd_backend(spd: Any, client: int, body: int) -> tuple[Any, Any]:
    """A bound jt SPD backend for the PyBullet body, from the registry (``jt.spd``).

    Args:
        spd: the ``spd`` group (dict or config node; ``name`` picks the backend), or None for maba.
        client: PyBullet client id.
        body: body id.

    Returns:
        ``(backend, model)``: the backend bound to ``Model.from_bullet(client, body)`` (fixed base,
        then the three root joints and the 16 hinges in PyBullet joint order), and that model.
    """
    from toolkit import plugins
    from toolkit.dynamics.model import Model
    from toolkit.interfaces.plugin import Plugin

    name = str(spd["name"]) if spd is not None and "name" in spd else "maba"
    backend = plugins.load("spd", name)({"name": name, **Plugin.params_of(spd)})
    if getattr(backend, "steps_itself", False):
        raise ValueError(f"spd={name} computes its torques inside stepSimulation; standing_jump "
                         "needs the torques (it adds the virtual-force torques and applies "
                         "limits): use maba, df, sf or pcg")
    model = Model.from_bullet(client, body)
    backend.bind(model)
    return backend, model


class _Episode:
    """The simulation loop of one jump and what it measures."""

    def __init__(self, p: Any, cid: int, robot: int, ground: int, names: list[str], body: Body,
                 ctrl: JumpController, st: SimSettings) -> None:
        self.p, self.cid, self.robot, self.ground, self.body, self.ctrl, self.st = p, cid, robot, ground, body, ctrl, st
        self.n = len(names)
        self.kin = PlanarKinematics(body, names)
        link_of = {p.getJointInfo(robot, i, physicsClientId=cid)[12].decode(): i for i in range(self.n)}
        self.body_index = {link_of[link.name]: k for k, link in enumerate(body.links)}
        self.feet = ctrl.feet
        self.jidx = [names.index(link.joint) for link in body.links[1:]]
        weights = effort_weights(body)
        self.w = [weights[link.joint] for link in body.links[1:]]
        self.head = body.links.index(body.link("head"))
        self.spd: Any = None  # a bound jt SPD backend (None: explicit PD)
        self.model: Any = None  # its toolkit.dynamics Model
        if st.stable_pd:
            self.spd, self.model = spd_backend(st.spd, cid, robot)

    def set_gravity(self, g: float) -> None:
        """Vertical gravity ``g`` (m/s²) for PyBullet and for the SPD model's bias forces."""
        self.p.setGravity(0.0, 0.0, g, physicsClientId=self.cid)
        if self.spd is not None:
            self.model.gravity[:] = (0.0, 0.0, g)  # the kernels read this array on every solve

    def contacts(self) -> dict[int, float]:
        """``{link index: total normal force}`` of the character's links touching the ground."""
        out: dict[int, float] = {}
        for c in self.p.getContactPoints(self.robot, self.ground, physicsClientId=self.cid):
            k = self.body_index.get(c[3])
            if k is not None:
                out[k] = out.get(k, 0.0) + c[9]
        return out

    def torques(self, q: list, qd: list, fr: Any, contacts: dict[int, float], dt: float) -> list[float]:
        """Joint torques ``(16,)`` in ``Body`` joint order (SPD or explicit PD, then limits)."""
        import numpy as np

        cmd = self.ctrl.command(fr, contacts, dt)
        if self.spd is None:
            tau = self.ctrl.pd(fr, cmd)
        else:  # the root's three DoFs keep zero gains: unactuated
            full = np.zeros((5, self.n))
            full[:, self.jidx] = [cmd.target, cmd.rate, cmd.kp, cmd.kd, cmd.extra]
            tau_full = self.spd.torques(np.asarray(q), np.asarray(qd), full[0], full[2], full[3], dt,
                                        qd_target=full[1]) + full[4]
            tau = [float(v) for v in tau_full[self.jidx]]
        return self.ctrl.finish(tau, fr, contacts)

    def run(self, gravity, g0: float, t_assist: float, record: bool, record_every: float,
            trace: Optional[list]) -> JumpResult:
        p, cid, robot, ctrl, st, body, kin = self.p, self.cid, self.robot, self.ctrl, self.st, self.body, self.kin
        dt = 1.0 / st.sim_hz
        all_j = list(range(self.n))
        e_je = e_se = 0.0
        lift = (0.0, 0.0, 0.0)
        apex_head = apex_com = -math.inf
        apex_q: list = []
        t_lift = t_land = None
        landing_x = math.nan
        start_x = None
        reason = ""
        snapshots: list = []
        last_phase = ctrl.phase
        q: list = []
        fr = None
        for step in range(int(st.max_time * st.sim_hz)):
            js = p.getJointStates(robot, all_j, physicsClientId=cid)
            q = [s[0] for s in js]
            qd = [s[1] for s in js]
            fr = kin.frame(q, qd)
            if not all(math.isfinite(v) for v in fr.com + fr.com_vel) or abs(fr.com_vel[0]) + abs(fr.com_vel[1]) > 50.0:
                reason = "unstable"
                break
            contacts = self.contacts()
            if contacts.keys() - self.feet:
                reason = "fall"
                break
            if record_every > 0 and step % max(int(round(record_every * st.sim_hz)), 1) == 0:
                snapshots.append((f"{ctrl.phase[:4]} {ctrl.t:.2f}", list(q)))
            if trace is not None:
                trace.append((ctrl.t, ctrl.phase, fr.com[0], fr.com[1], fr.com_vel[0], fr.com_vel[1],
                               fr.pitch[0], fr.pitch[2], kin.angular_momentum(fr)))
            if start_x is None:
                start_x = ctrl.support_x(fr)
            tau = self.torques(q, qd, fr, contacts, dt)
            if ctrl.phase != last_phase:
                if ctrl.phase == "rise":
                    t_lift = ctrl.t - dt
                    lift = (fr.com_vel[1], fr.com_vel[0], kin.angular_momentum(fr))
                elif ctrl.phase == "land":
                    t_land = ctrl.t - dt
                    landing_x = ctrl.support_x(fr) - start_x
                if record and not record_every:
                    snapshots.append((ctrl.phase, list(q)))
                last_phase = ctrl.phase
            if ctrl.phase in ("rise", "fall"):
                hz = fr.link_com[self.head][1]
                if hz > apex_head:
                    apex_head, apex_q = hz, list(q)
                apex_com = max(apex_com, fr.com[1])
            if ctrl.phase == "takeoff" and ctrl.t_phase > st.timing.takeoff_max:
                reason = "no_takeoff"
                break
            if ctrl.finished:
                break
            forces = [0.0] * self.n
            for i, j in enumerate(self.jidx):
                forces[j] = tau[i]
                e_je += self.w[i] * tau[i] * tau[i] * dt
            if t_lift is not None and t_land is None and t_assist > 0.0:
                g = gravity(ctrl.t - t_lift)
                if g != P.NATURAL_GRAVITY:
                    f = body.mass * (g - P.NATURAL_GRAVITY)  # the external force equivalent to the reduced gravity
                    e_se += f * f * dt
                self.set_gravity(g)
            elif t_land is not None and t_assist > 0.0:
                self.set_gravity(P.NATURAL_GRAVITY)
            p.setJointMotorControlArray(robot, all_j, p.TORQUE_CONTROL, forces=forces, physicsClientId=cid)
            p.stepSimulation(physicsClientId=cid)
        else:
            reason = "no_landing" if t_land is None else "no_recovery"

        if not reason and fr is not None:
            if fr.link_com[self.head][1] < st.upright_fraction * standing_head_height(body):
                reason = "not_upright"
            elif not abs(landing_x - st.landing_target) <= st.landing_tolerance:
                reason = "landing_outside_box"
        if record and not record_every:
            if apex_q:
                snapshots.append(("apex", apex_q))
            order = ["crouch", "takeoff", "rise", "apex", "fall", "land"]
            snapshots.sort(key=lambda s: order.index(s[0]) if s[0] in order else 99)
        if record and q:
            snapshots.append(("end", list(q)))
        if t_lift is None:
            apex_head, apex_com = standing_head_height(body), math.nan
        return JumpResult(
            success=not reason, reason=reason, height=float(apex_head), com_height=float(apex_com),
            e_je=float(e_je), e_se=float(e_se), takeoff_gravity=float(g0), assist_time=float(t_assist),
            landing_x=float(landing_x), flight_time=float(t_land - t_lift) if (t_land and t_lift) else 0.0,
            sim_time=float(ctrl.t), liftoff_velocity=float(lift[0]), liftoff_vx=float(lift[1]),
            liftoff_momentum=float(lift[2]), events=list(ctrl.events), snapshots=snapshots)
