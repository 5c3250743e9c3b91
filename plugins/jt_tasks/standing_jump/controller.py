"""The finite-state jump controller of ``004`` §3.1 (Fig. 2): stand → crouch → take-off → rise
(flight) → fall → land.

Every joint is PD-servoed; targets move piecewise-linearly from the previous phase's targets to
the current phase's. The feet and the upper torso (chest) are servoed to world-frame angles, and
so is the pelvis while a foot carries weight (through the stance hips, as in SIMBICON); the other
joints servo local angles (§3: "The feet, pelvis and upper torso are servoed to target angles
that are expressed in the world coordinate frame"). World-frame targets are turned into joint
targets ``q* = theta* - axis * parent_pitch`` with target rate ``-axis * parent_rate``, so a joint
PD (or Stable PD) on them servos the world angle and damps the world rate. On top of that:

* stand, crouch, take-off, land: a horizontal virtual force on the centre of mass, realised with
  internal torques ``tau = J^T f`` on each stance leg's ankle, knee and hip (Coros et al. 2010),
  keeps the CoM over the feet; in the landing phase it also damps the horizontal momentum away.
* rise: the time to the apex is predicted and sets the duration of the target ramp.
* fall: time and place of touch-down are predicted; leg IK aims the ankles so that the landing's
  capture point falls on the feet (``placement``).
* stance ankles keep the centre of pressure inside the sole; at take-off under the CoM, so the
  push-off does not spin the body.

The controller is pure Python: it sees a ``Frame`` and the ground contacts and returns joint
targets, gains and extra torques; ``simulate`` turns them into torques with PyBullet.
"""

from __future__ import annotations

import dataclasses
from typing import Callable, Optional

from jt_tasks.standing_jump import placement
from jt_tasks.standing_jump.kinematics import Frame
from jt_tasks.standing_jump.model import Body
from jt_tasks.standing_jump.timing import Timing

# per joint class: kp (N m/rad), kd (N m s/rad), torque limit (N m); fixed, tuned by hand (004 §3)
GAINS = {
    "hip": (1000.0, 100.0, 300.0),
    "knee": (1000.0, 60.0, 300.0),
    "ankle": (300.0, 30.0, 150.0),
    "abs": (1000.0, 100.0, 300.0),
    "back": (1000.0, 100.0, 300.0),
    "neck": (100.0, 10.0, 50.0),
    "head": (100.0, 10.0, 30.0),
    "shoulder": (300.0, 30.0, 100.0),
    "elbow": (150.0, 15.0, 60.0),
    "wrist": (20.0, 2.0, 10.0),
}
WORLD_FRAME = ("back", "ankle")
"""Joint classes servoed to a world-frame angle of their child link (chest lean, foot pitch)."""

STANCE = ("stand", "crouch", "takeoff", "land")


@dataclasses.dataclass
class Command:
    """What the controller asks for at one step; lists are over the 16 joints in ``Body`` order.

    Attributes:
        target: joint-space PD targets (rad).
        rate: target joint rates (rad/s).
        kp: stiffness per joint (N m/rad).
        kd: damping per joint (N m s/rad).
        extra: torques added after the PD (virtual force), N m.
    """

    target: list[float]
    rate: list[float]
    kp: list[float]
    kd: list[float]
    extra: list[float]


class JumpController:
    """Finite-state machine + PD targets + virtual force + foot-placement IK for one jump.

    Args:
        body: the character.
        targets: ``{phase: {joint class: angle}}`` (``params.phase_targets``).
        timing: phase timing and feedback gains.
        gravity: ``g(t)``: gravity along z ``t`` seconds after take-off (m/s², negative).
    """

    def __init__(self, body: Body, targets: dict[str, dict[str, float]], timing: Timing,
                 gravity: Callable[[float], float] = lambda t: -9.8) -> None:
        self.body = body
        self.targets = targets
        self.tm = timing
        self.gravity = gravity
        self.names = [link.name for link in body.links]
        self.joints = body.links[1:]
        self.cls = [link.joint_class for link in self.joints]
        self.parent = [self.names.index(link.parent) if link.parent else -1 for link in body.links]
        s = timing.gains_scale
        self.kp = [GAINS[c][0] * s for c in self.cls]
        self.kd = [GAINS[c][1] * s for c in self.cls]
        self.limit = [GAINS[c][2] for c in self.cls]
        self.legs = [tuple(self.names.index(f"{n}_{side}") for n in ("thigh", "shank", "foot"))
                     for side in ("l", "r")]  # link indices per side
        self.feet = {leg[2] for leg in self.legs}
        self.foot_of = {leg[0]: leg[2] for leg in self.legs}
        self.full_load = 0.15 * body.mass * 9.8  # a foot carrying this much is fully a stance foot
        self.phase = "stand"
        self.t = 0.0
        self.t_phase = 0.0
        self.keys: list[tuple[float, dict[str, float]]] = [(0.0, dict(targets["stand"]))]
        self.t_liftoff: Optional[float] = None
        self.t_rise: Optional[float] = None
        self.balance_x: Optional[float] = None
        self.events: list[tuple[str, float]] = [("stand", 0.0)]
        self._airborne = 0.0
        self._dt = 0.0

    # ---- piecewise-linear targets -------------------------------------------------------------
    def current_targets(self) -> dict[str, float]:
        """Targets now, per joint class: linear between the phase's key frames, held after the last."""
        return self._targets_and_rates()[0]

    def _targets_and_rates(self) -> tuple[dict[str, float], dict[str, float]]:
        """Targets and their time derivatives (the slopes of the piecewise-linear ramps)."""
        t, keys = self.t_phase, self.keys
        for (t0, a), (t1, b) in zip(keys, keys[1:]):
            if t < t1:
                w = (t - t0) / (t1 - t0)
                return ({k: a[k] + w * (b[k] - a[k]) for k in b}, {k: (b[k] - a[k]) / (t1 - t0) for k in b})
        last = keys[-1][1]
        return dict(last), dict.fromkeys(last, 0.0)

    def _enter(self, phase: str, keys: list[tuple[float, dict[str, float]]], fr: Frame) -> None:
        """Switch phase; targets ramp from the current ones through ``keys`` ``[(time, targets)]``.

        Where the hip target changes meaning (pelvis pitch in stance, hip angle in flight) the ramp
        starts from the measured value of the new quantity.
        """
        now = self.current_targets()
        if (phase in STANCE) != (self.phase in STANCE):
            thigh = self.legs[0][0]
            now["hip"] = fr.pitch[0] if phase in STANCE else fr.pitch[0] - fr.pitch[thigh]
        self.keys = [(0.0, now)]
        for t, k in keys:
            self.keys.append((max(t, self.keys[-1][0] + 1e-6), dict(k)))
        self.phase = phase
        self.t_phase = 0.0
        self.events.append((phase, self.t))

    # ---- state machine ------------------------------------------------------------------------
    @property
    def finished(self) -> bool:
        """True once the character has landed, stood up and held the standing pose."""
        return (self.phase == "land" and self.t_rise is not None
                and self.t_phase >= self.t_rise + self.tm.land_rise + self.tm.stand_hold)

    def feet_height(self, fr: Frame) -> float:
        """Height of the soles (the lower ankle minus the ankle height), m."""
        return min(fr.joint_pos[leg[2]][1] for leg in self.legs) - self.body.ankle_height

    def support_x(self, fr: Frame, where: Optional[float] = None) -> float:
        """Horizontal point along the feet (``where``: heel 0 → toe 1, default ``balance_point``)."""
        b = self.body
        off = (self.tm.balance_point if where is None else where) * b.foot_length - b.heel_to_ankle
        return sum(fr.joint_pos[leg[2]][0] for leg in self.legs) / 2.0 + off

    def _transition(self, fr: Frame, contacts: dict[int, float]) -> None:
        tg, tm = self.targets, self.tm
        on_ground = bool(contacts.keys() & self.feet)
        if self.phase == "stand" and self.t_phase >= tm.stand_time:
            self._enter("crouch", [(tm.crouch_ramp, tg["crouch"])], fr)
        elif self.phase == "crouch" and self.t_phase >= tm.crouch_time:
            self.balance_x = self.support_x(fr, tm.takeoff_balance_point)
            self._enter("takeoff", [(tm.takeoff_ramp, tg["takeoff"])], fr)
        elif self.phase == "takeoff":
            self._airborne = 0.0 if on_ground else self._airborne + self._dt
            if self._airborne >= tm.liftoff_time - 1e-9:
                self.t_liftoff = self.t
                t_apex = placement.time_to_apex(fr.com_vel[1], self.gravity)
                self._enter("rise", [(t_apex, tg["rise"])], fr)
        elif self.phase == "rise" and fr.com_vel[1] <= 0.0:
            t_td = placement.time_to_touchdown(self.feet_height(fr), fr.com_vel[1])
            self._enter("fall", [(t_td, tg["fall"])], fr)
        elif self.phase == "fall" and on_ground:
            self.balance_x = self.support_x(fr)
            self._enter("land", [(tm.land_absorb, tg["land"])], fr)
        elif self.phase == "land" and self.t_rise is None and self.t_phase >= tm.land_absorb:
            settled = abs(fr.com_vel[0]) < tm.settle_speed and abs(fr.com[0] - self.balance_x) < tm.settle_offset
            if settled or self.t_phase >= tm.land_hold_max:
                self.t_rise = self.t_phase
                self.keys = [(self.t_phase, self.current_targets()), (self.t_phase + tm.land_rise, dict(tg["stand"]))]

    # ---- the control step ---------------------------------------------------------------------
    def command(self, fr: Frame, contacts: dict[int, float], dt: float) -> Command:
        """Advance the state machine by ``dt`` and return the joint targets, gains and extra torques.

        Args:
            fr: kinematic state now.
            contacts: ``{link index (into body.links): normal force (N)}`` of links on the ground.
            dt: control period (s).
        """
        if self.balance_x is None:
            self.balance_x = self.support_x(fr)
        self._dt = dt
        self._transition(fr, contacts)
        cmd = self._joint_targets(fr, contacts)
        if self.phase in STANCE and contacts.keys() & self.feet:
            self._virtual_force(fr, cmd.extra)
        self.t += dt
        self.t_phase += dt
        return cmd

    def _joint_targets(self, fr: Frame, contacts: dict[int, float]) -> Command:
        tgt, rate = self._targets_and_rates()
        stance = self.phase in STANCE
        if self.phase == "fall":
            tgt = dict(tgt)
            tgt["hip"], tgt["knee"] = self._foot_placement(fr, tgt)
        lean = 0.0
        if self.phase == "land":  # hip strategy: lean into a CoM that runs ahead
            lean = self.tm.hip_balance_kp * (fr.com[0] - self.balance_x) + self.tm.hip_balance_kd * fr.com_vel[0]
        n = len(self.joints)
        target, trate = [0.0] * n, [0.0] * n
        for i, link in enumerate(self.joints):
            c, k = self.cls[i], i + 1  # k: index into body.links / frame arrays
            p = self.parent[k]
            q_c, r_c = tgt[c], rate[c]
            if c in WORLD_FRAME:  # world angle axis * pitch_k = axis * pitch_p + q
                q_c, r_c = q_c - link.axis * fr.pitch[p], -link.axis * fr.omega[p]
            elif c == "hip" and stance:
                load = min(contacts.get(self.foot_of[k], 0.0) / self.full_load, 1.0)
                if load > 0.0:  # pelvis pitch = thigh pitch + hip angle: servo it through the hip
                    q_c = load * (tgt[c] + lean - fr.pitch[k]) + (1.0 - load) * q_c
                    r_c = load * (rate[c] - fr.omega[k]) + (1.0 - load) * r_c
            target[i], trate[i] = q_c, r_c
        return Command(target, trate, list(self.kp), list(self.kd), [0.0] * n)

    def pd(self, fr: Frame, cmd: Command) -> list[float]:
        """Explicit PD torques ``kp (q* - q) + kd (qd* - qd)`` for a command (no limits)."""
        out = []
        for i, link in enumerate(self.joints):
            k = i + 1
            p = self.parent[k]
            q = link.axis * (fr.pitch[k] - fr.pitch[p])
            qd = link.axis * (fr.omega[k] - fr.omega[p])
            out.append(cmd.kp[i] * (cmd.target[i] - q) + cmd.kd[i] * (cmd.rate[i] - qd) + cmd.extra[i])
        return out

    def finish(self, tau: list[float], fr: Frame, contacts: dict[int, float]) -> list[float]:
        """Torque limits, then the stance feet's centre-of-pressure limits (in place)."""
        for i, lim in enumerate(self.limit):
            tau[i] = min(max(tau[i], -lim), lim)
        if self.phase in STANCE:
            self._limit_cop(fr, contacts, tau)
        return tau

    def _virtual_force(self, fr: Frame, tau: list[float]) -> None:
        """Add ``J^T f`` for a horizontal CoM force ``f`` split over the two stance legs.

        The torque each leg joint must exert on the body above it is ``(r_com - r_joint) x f``
        (Coros et al. 2010); the motor torque of a joint acts with the opposite sign on its parent.
        """
        tm = self.tm
        kd = tm.vf_kd_land if self.phase == "land" else tm.vf_kd
        fx = 0.5 * (tm.vf_kp * (self.balance_x - fr.com[0]) - kd * fr.com_vel[0])  # per leg
        cz = fr.com[1]
        for leg in self.legs:
            for k in leg:  # thigh (hip joint), shank (knee), foot (ankle)
                torque_on_upper = (cz - fr.joint_pos[k][1]) * fx  # (r x f)_y with f = (fx, 0)
                tau[k - 1] -= self.body.links[k].axis * torque_on_upper

    def _limit_cop(self, fr: Frame, contacts: dict[int, float], tau: list[float]) -> None:
        """Keep each loaded foot's centre of pressure inside the sole (and, at take-off, under the CoM).

        A foot with normal force ``F`` and ankle torque ``u`` (dorsiflexion +) has its centre of
        pressure ``-u / F`` ahead of the ankle. Torques that would move it past the heel or the toes
        only tip the foot, so they are capped (``cop_margin`` inside the sole). At take-off the
        push-off stays within ``takeoff_cop_margin`` of the CoM: the vertical push then exerts no
        moment about the CoM, and the body leaves the ground without spinning.
        """
        b, tm = self.body, self.tm
        toe = b.foot_length - b.heel_to_ankle - tm.cop_margin
        heel = b.heel_to_ankle - tm.cop_margin
        for leg in self.legs:
            foot = leg[2]
            f = contacts.get(foot, 0.0)
            if f <= 0.0:
                continue  # a foot off the ground keeps its PD torque
            lo, hi = -toe, heel
            if self.phase == "takeoff":
                d = fr.com[0] - fr.joint_pos[foot][0]
                lo = max(lo, -(d + tm.takeoff_cop_margin))
                hi = min(hi, -(d - tm.takeoff_cop_margin))
            tau[foot - 1] = min(max(tau[foot - 1], f * lo), f * max(hi, lo))

    def _foot_placement(self, fr: Frame, tgt: dict[str, float]) -> tuple[float, float]:
        """Hip and knee targets aiming the ankles so the landing's capture point is on the feet.

        Touch-down time and CoM are predicted ballistically; the ankle is aimed so that the
        capture point ``x + vx sqrt(h / g)`` at touch-down falls on the balance point of the foot.
        """
        b, tm = self.body, self.tm
        thigh, shank, foot = self.legs[0]
        t_td = placement.time_to_touchdown(self.feet_height(fr), fr.com_vel[1])
        vx = fr.com_vel[0]
        capture = fr.com[0] + vx * t_td + vx * (tm.landing_height / 9.8) ** 0.5
        hip_x = fr.joint_pos[thigh][0] + vx * t_td
        dx = capture - (tm.balance_point * b.foot_length - b.heel_to_ankle) - hip_x
        return placement.leg_ik(dx, fr.pitch[0], tgt["hip"], tgt["knee"], -b.links[shank].origin[2],
                                -b.links[foot].origin[2], tm.ik_knee_min, tm.ik_knee_max, tm.ik_limit)
