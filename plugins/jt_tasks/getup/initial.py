"""Initial states of the get-up episodes (``003`` §5.2, §5.5).

* ``clip_pose``: a frame of a get-up clip (its first pose starts the clip's own curve, §5.5 "The
  initial posture of each reference motion is used to initialize the character"; its last frame
  is a standing pose, §5.2 (ii)), velocities from the clip by central differences, lifted so that
  no part is below the ground (the clips' feet dip into their floor by a few cm).
* ``fallen_states``: a seeded passive rag-doll generator (§5.2: "dropping a passive rag-doll
  model with a prone or supine posture onto the terrain"): the standing pose laid prone or supine
  with a random heading and random joint perturbations, released above the ground with the PD
  servos off (kp = 0, a small joint damping), simulated until at rest (every generalised speed
  below ``rest_speed``) and accepted then; a drop not at rest within ``settle_max`` s is redrawn.
* ``symmetric_legs``: a stance with one leg the mirror image of the other (``task.stand_pose``).
* ``pick_curve``: a curve whose starting torso angles are within 30° of a state's (§5.2), else
  the nearest one.
"""

from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np

from toolkit.motion import rotations as rot

from jt_tasks.getup.ground import lift_to_ground

STYLES = ("prone", "supine")  #: the rag-doll drop postures (003 §5.2)
STAND_POSES = ("clip", "symmetric")  #: ``task.stand_pose``: the standing pose (``symmetric_legs``)


def clip_pose(clip: str, mirrored: bool = False, frame: int = 0, ground: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """``(q (n_q,), qd (n_dof,))`` of a get-up clip's frame (0: the first, -1: the last),
    ``toolkit.dynamics`` layout, resting ``CLEARANCE`` above ``ground``."""
    from jt_tasks.getup.curves import load_getup_clip
    from jt_tasks.takeoff.state import reference_state

    c = load_getup_clip(clip, mirrored)
    t = float(c.times[frame])
    t = min(max(t, 1.0 / 120.0), float(c.times[-1]) - 1.0 / 120.0)  # central differences inside the clip
    p, r, j, v, w, jv = reference_state(c, t)
    q = lift_to_ground(np.concatenate([p, r, j]), ground)
    return q, np.concatenate([v, w, jv])


def symmetric_legs(q: np.ndarray, source: str = "left") -> np.ndarray:
    """``q`` ``(n_q,)`` with the other leg's hip, knee and ankle the mirror image (across the
    character's sagittal plane) of the ``source`` leg's: a stance with both feet alike."""
    from toolkit.motion.skeletons import HUMANOID

    q = np.array(q, dtype=np.float64)
    mirrored = HUMANOID.mirror_joints(q[7:])
    other = "right" if source == "left" else "left"
    for part in ("hip", "knee", "ankle"):
        s = HUMANOID.q_slices[f"{other}_{part}"]
        q[7 + s.start:7 + s.stop] = mirrored[s]
    return q


def clip_state_at(clip: str, mirrored: bool, t: float, duration: Optional[float] = None,
                  ground: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """``(q (n_q,), qd (n_dof,))`` of a get-up clip ``t`` s into a curve of ``duration`` s (None:
    the clip's own), the clip's time scaled to it and its velocities with it, resting
    ``CLEARANCE`` above ``ground`` (a reference-state-initialisation start)."""
    from jt_tasks.getup.curves import load_getup_clip
    from jt_tasks.takeoff.state import reference_state

    c = load_getup_clip(clip, mirrored)
    length = float(c.times[-1] - c.times[0])
    scale = 1.0 if not duration else length / float(duration)
    tc = float(c.times[0]) + float(t) * scale
    tc = min(max(tc, float(c.times[0]) + 1.0 / 120.0), float(c.times[-1]) - 1.0 / 120.0)
    p, r, j, v, w, jv = reference_state(c, tc)
    q = lift_to_ground(np.concatenate([p, r, j]), ground)
    return q, np.concatenate([v, w, jv]) * scale


def lay_down(q_stand: np.ndarray, style: str, yaw: float, height: float) -> np.ndarray:
    """The standing pose ``q_stand`` turned to lie ``prone`` or ``supine`` (about the world z axis of
    a character facing +x), then turned by ``yaw`` about +y, root at ``height``."""
    if style not in STYLES:
        raise ValueError(f"unknown fallen style {style!r}: {', '.join(STYLES)}")
    q = np.array(q_stand, dtype=np.float64)
    tilt = rot.quat_from_axis_angle(np.array([0.0, 0.0, 1.0]), (-math.pi / 2) if style == "prone" else (math.pi / 2))
    turn = rot.quat_from_axis_angle(np.array([0.0, 1.0, 0.0]), float(yaw))
    q[3:7] = rot.quat_normalize(rot.quat_multiply(turn, rot.quat_multiply(tilt, q[3:7])))
    q[0], q[1], q[2] = 0.0, float(height), 0.0
    return q


def perturb_joints(q: np.ndarray, rng: np.random.Generator, scale: float) -> np.ndarray:
    """Joint rotations of ``q`` perturbed by random rotations of up to ``scale`` rad (spherical:
    a random exp map, revolute: a uniform offset)."""
    from toolkit.motion.skeletons import HUMANOID, SPHERICAL

    q = np.array(q, dtype=np.float64)
    joints = q[7:]
    for j, s in zip(HUMANOID.joints, HUMANOID.q_slices.values()):
        if j.kind == SPHERICAL:
            d = rng.uniform(-scale, scale, 3)
            joints[s] = rot.quat_normalize(rot.quat_multiply(joints[s], rot.quat_from_expmap(d)))
        else:
            joints[s] = joints[s] + rng.uniform(-scale, scale)
    q[7:] = joints
    return q


def passive_groups(sim_groups: dict, kd: float, sim_hz: Optional[float] = None) -> dict:
    """The simulator groups with the PD servos off (kp = 0) and joint damping ``kd``: a rag-doll;
    simulated at ``sim_hz`` when given."""
    out = {k: dict(v or {}) for k, v in sim_groups.items()}
    if sim_hz:
        out["sim"] = {**out.get("sim", {}), "sim_hz": float(sim_hz)}
    out["character"] = {**out.get("character", {}), "kp": 0.0, "kd": float(kd),
                        "joint_kp": {}, "joint_kd": {}}
    return out


def fallen_states(sim_groups: dict, n: int, seed: int, styles: Sequence[str] = STYLES, drop_height: float = 0.6,
                  perturb: float = 0.3, kd: float = 1.0, settle_max: float = 3.0, rest_speed: float = 0.05,
                  max_tries: int = 4, terrain: Optional[dict] = None, region: int = 0,
                  sim_hz: Optional[float] = None) -> list[dict]:
    """``n`` settled rag-doll states on the ground, seeded: ``[{q, qd, style, settle_s, at_rest,
    region, xz}]`` (lists).

    Args:
        sim_groups: ``{"sim", "spd", "character"}`` plain groups (the env's; PD servos switched off here).
        n: states wanted; ``seed``: their generator's seed (the same seed gives the same states).
        styles: drop postures cycled through (``prone``, ``supine``).
        drop_height: m, root height at release (ours).
        perturb: rad, joint perturbation of the drop pose (ours).
        kd: N m s/rad, the rag-doll's joint damping (ours; 0 is frictionless joints).
        settle_max: s of simulation allowed to come to rest (notes: drops settle within 3 s).
        rest_speed: at rest when every generalised speed is below this (rad/s, m/s).
        max_tries: drops per state before the last one is accepted as it is.
        terrain: a ``terrain.TerrainSpec`` dict: the terrain is built and each drop lands at a
            seeded location of ``region`` (003 §5.2 "onto the terrain at various locations");
            None or region 0: dropped at the origin of the flat ground.
        region: the terrain region (0 flat .. 3 hard).
        sim_hz: the drops' simulation rate (None: the env's); a passive rag-doll settles the same
            at 60-600 Hz (notes), so a low rate makes drops cheap.

    A drop the simulator flags as failed (exploded) is never accepted: it is drawn again, up to
    ``3 * max_tries`` times, then ``RuntimeError``.
    """
    from toolkit.policy.env import load_simulator

    if n <= 0:
        return []
    from jt_tasks.getup import terrain as T

    rng = np.random.default_rng(int(seed))
    sim = load_simulator(passive_groups(sim_groups, kd, sim_hz))
    q_stand, _ = clip_pose("getup_facedown", False, frame=-1)
    tspec = T.TerrainSpec.from_dict(terrain) if terrain is not None and region > 0 else None
    if tspec is not None:
        T.add_terrain(sim, tspec, sim.friction)
        where = T.sample_locations(tspec, int(region), n, np.random.default_rng([int(seed), int(region)]))
    out = []
    try:
        steps = int(round(settle_max * float(sim.control_hz)))
        for i in range(n):
            style = styles[i % len(styles)]
            xz = where[i] if tspec is not None else np.zeros(2)
            for attempt in range(3 * max_tries):
                q0 = perturb_joints(lay_down(q_stand, style, rng.uniform(-math.pi, math.pi), 1.0), rng, perturb)
                if tspec is not None:
                    q0 = T.place_on_ground(sim, q0, np.zeros(sim.model.n_v), xz, drop_height)
                else:
                    q0 = lift_to_ground(q0, 0.0, drop_height)
                sim.reset(q0, np.zeros(sim.model.n_v))
                rest, failed, t = False, False, 0.0
                for k in range(steps):
                    q, qd = sim.state()
                    rec = sim.step(q)
                    t = (k + 1) / float(sim.control_hz)
                    if rec["failed"]:
                        failed = True
                        break
                    if k > 3 and float(np.max(np.abs(rec["qd"]))) < rest_speed:
                        rest = True
                        break
                if failed and attempt == 3 * max_tries - 1:
                    raise RuntimeError(f"fallen_states: every drop of state {i} failed ({rec['reason']})")
                if not failed and (rest or attempt >= max_tries - 1):
                    q, qd = sim.state()
                    out.append({"q": q.tolist(), "qd": qd.tolist(), "style": style, "settle_s": t, "at_rest": rest,
                                "region": int(region) if tspec is not None else 0, "xz": [float(v) for v in xz]})
                    break
    finally:
        sim.close()
    return out


def pick_curve(start_angles: np.ndarray, curve_starts: np.ndarray, rng: np.random.Generator,
               max_deg: float = 30.0) -> int:
    """Index of a curve whose start torso angles ``(θx, θz)`` are each within ``max_deg`` of
    ``start_angles`` (``003`` §5.2), uniformly among them; none: the nearest (L1) curve."""
    d = np.abs(np.asarray(curve_starts, float)[:, 1:] - np.asarray(start_angles, float)[-2:])
    ok = np.nonzero(np.all(d <= math.radians(max_deg), axis=1))[0]
    if len(ok):
        return int(ok[rng.integers(len(ok))])
    return int(np.argmin(d.sum(axis=1)))
