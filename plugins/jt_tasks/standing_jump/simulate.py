"""One standing jump: build the world, run the controller, measure the result.

The world is the simulator plugin's planar world (``sim=bullet``: ``jt_bullet.planar``), found
through the registry: the planar URDF of ``model.write_urdf`` on a ground plane in a world of its
own per call (nothing shared between evaluations, so the same parameters give the same result),
the default joint motors off, the controller's torques applied at every simulation step
(``sim_hz``, 600 Hz by default). The PD targets become torques by Stable PD, solved by one of
jt's SPD backends (``spd=maba|df|sf|pcg``, loaded through the plugin registry) on the world's
``toolkit.dynamics`` model of the body. The supernatural assist of ``004`` §3.3 is reduced
gravity after take-off, ramping back to -9.8 m/s² over the assist duration; it is set on the world
only while it differs from normal gravity, so a natural controller runs with exactly zero external
force.
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
from toolkit.errors import JtError


class UnusableSPD(JtError):
    """The ``spd`` group names a backend standing_jump cannot use (a one-line ``JtError``)."""


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
        sim: registry name of the simulator plugin whose planar world runs the jump (``bullet``).
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
    sim: str = "bullet"


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


def planar_world(body: Body, friction: float, sim_hz: float,
                 rgba: tuple = (0.55, 0.36, 0.2, 1.0), sim: str = "bullet") -> Any:
    """The simulator plugin's planar world with the character standing at x = 0.

    Args:
        body: the character (its URDF is written by ``write_urdf``, cached).
        friction: ground and foot Coulomb friction coefficient.
        sim_hz: simulation rate, Hz.
        rgba: the character's colour.
        sim: registry name of the simulator plugin (``jt.simulators``) that has a planar world.

    Returns:
        A planar world (``jt_bullet.planar.PlanarWorld`` for ``sim=bullet``): ``joint_names``,
        ``link_names``, ``joint_states()``, ``apply_torques``, ``step``, ``render`` ...; the
        caller closes it.

    Raises:
        JtError: the simulator has no planar world.
    """
    from toolkit import plugins

    factory = getattr(plugins.load("sim", str(sim)), "planar_world", None)
    if factory is None:
        raise JtError(f"sim={sim} has no planar world (planar_world); standing_jump runs on "
                      "sim=bullet")
    world = factory(write_urdf(body, rgba), sim_hz=sim_hz, friction=friction,
                    gravity=P.NATURAL_GRAVITY)
    world.reset_joint(world.joint_names.index("root_z"), body.hip_height + 1e-4)
    return world


def open_world(body: Body, friction: float, sim_hz: float,
               rgba: tuple = (0.55, 0.36, 0.2, 1.0), sim: str = "bullet") -> tuple[int, int, int, list[str]]:
    """``planar_world`` as raw PyBullet handles, for tests that check against PyBullet itself.

    Returns:
        ``(client id, robot id, ground id, joint names)``; the caller disconnects the client.
    """
    w = planar_world(body, friction, sim_hz, rgba, sim)
    return w.client, w.robot, w.ground, list(w.joint_names)


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
    st = settings or SimSettings()
    body = build_body(st.mass, st.height)
    g0, t_assist = P.assist(point, st.assist_deadzone)

    def gravity(t: float) -> float:
        if t_assist == 0.0 or t >= t_assist:
            return P.NATURAL_GRAVITY
        return g0 + (P.NATURAL_GRAVITY - g0) * (t / t_assist)

    ctrl = JumpController(body, P.phase_targets(point), st.timing, gravity)
    world = planar_world(body, st.friction, st.sim_hz, sim=st.sim)
    try:
        ep = _Episode(world, body, ctrl, st)
        return ep.run(gravity, g0, t_assist, record, record_every, trace)
    finally:
        world.close()


def spd_solver(spd: Any) -> Any:
    """An (unbound) jt SPD backend from the registry (``jt.spd``) that returns torques.

    Args:
        spd: the ``spd`` group (dict or config node; ``name`` picks the backend), or None for maba.

    Raises:
        UnusableSPD: the backend computes its torques inside the simulation step (``bullet``).
    """
    from toolkit import plugins
    from toolkit.interfaces.plugin import Plugin

    name = str(spd["name"]) if spd is not None and "name" in spd else "maba"
    backend = plugins.load("spd", name)({"name": name, **Plugin.params_of(spd)})
    if getattr(backend, "steps_itself", False):
        raise UnusableSPD(f"spd={name} computes its torques inside stepSimulation; standing_jump "
                          "needs the torques (it adds the virtual-force torques and applies "
                          "limits): use maba, df, sf or pcg")
    return backend


class _Episode:
    """The simulation loop of one jump and what it measures."""

    def __init__(self, world: Any, body: Body, ctrl: JumpController, st: SimSettings) -> None:
        self.world, self.body, self.ctrl, self.st = world, body, ctrl, st
        names = world.joint_names
        self.n = len(names)
        self.kin = PlanarKinematics(body, names)
        link_of = {name: i for i, name in enumerate(world.link_names)}
        self.body_index = {link_of[link.name]: k for k, link in enumerate(body.links)}
        self.feet = ctrl.feet
        self.jidx = [names.index(link.joint) for link in body.links[1:]]
        weights = effort_weights(body)
        self.w = [weights[link.joint] for link in body.links[1:]]
        self.head = body.links.index(body.link("head"))
        self.spd: Any = None  # a bound jt SPD backend (None: explicit PD)
        self.model: Any = None  # its toolkit.dynamics Model
        if st.stable_pd:
            self.spd = spd_solver(st.spd)
            self.model = world.model()
            self.spd.bind(self.model)

    def set_gravity(self, g: float) -> None:
        """Vertical gravity ``g`` (m/s²) for the world and for the SPD model's bias forces."""
        self.world.set_gravity(g)
        if self.spd is not None:
            self.model.gravity[:] = (0.0, 0.0, g)  # the kernels read this array on every solve

    def contacts(self) -> dict[int, float]:
        """``{link index: total normal force}`` of the character's links touching the ground."""
        out: dict[int, float] = {}
        for link, force in self.world.ground_contacts():
            k = self.body_index.get(link)
            if k is not None:
                out[k] = out.get(k, 0.0) + force
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
        world, ctrl, st, body, kin = self.world, self.ctrl, self.st, self.body, self.kin
        dt = 1.0 / st.sim_hz
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
            q, qd = world.joint_states()
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
            world.apply_torques(forces)
            world.step()
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
