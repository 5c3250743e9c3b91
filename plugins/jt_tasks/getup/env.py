"""The get-up environment (``003`` §3.3, §5.1-5.3, §5.6): track style curves from a fallen state.

An episode: a feature curve (``curves.FeatureCurve``) and an initial state (``003`` §5.2): the
curve's clip's first pose, a settled rag-doll state (a curve whose start torso angles are within
30° of it), or a standing pose (the curve then starts at ``s = 1``, the standing phase). It lasts
``T + T_stand`` (3 s, §5.6) and ends early (§5.3) when ``r_task < r_task_min`` (0.1) or the head
touches the ground for more than 300 ms in a row (head contacts count only after ``head_grace`` s
when the head lies on the floor, or within 15 cm of it, at t = 0: supine clip starts and rag-doll
states). ``info["success"]`` counts fallen starts only (standing starts: ``standing_success``), so
the terrain curriculum counts get-ups. Control at the simulator's ``control_hz`` (30 Hz,
§5.6), ``sim_hz / control_hz`` substeps (600 Hz here; 003 simulates at 60 Hz).

Reward per control step: ``r = r_task · r_natural`` (eq 2), the product of the ``reward`` group's
jt.rewards terms (``conf/reward/getup.yaml``: eqs 4-9 and the action space's eq 3); ``r_task`` is
the product of all but ``natural_terms``.

Observation ``(obs_dim,)`` float32, ``003`` §3.3 in the heading frame (``features.heading_yaw``):
link orientations (the base and 15 PyBullet links: 16 × 4, quaternions, w ≥ 0), link positions
relative to the root (16 × 3), link angular and linear velocities (16 × 3 each; finite differences over the last control step,
zero after a reset: ours, the simulator gives no link velocities), the features (h, θx, θz), the
5 × 5 height map (hip height above the ground, 1 m × 1 m), the curve targets at +0/100/200/300 ms
(4 × 3) and the previous filtered action (``action=cvae``; the previous action for other spaces).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Optional

import numpy as np

from jt_tasks.getup import features as F
from jt_tasks.getup.config import GetupConfig as _C
from jt_tasks.getup import kernels
from jt_tasks.getup.curves import FeatureCurve
from jt_tasks.getup.ground import lift_to_ground
from jt_tasks.getup.initial import clip_pose, clip_state_at, perturb_joints, pick_curve, symmetric_legs
from jt_tasks.getup.terrain import TerrainSpec, add_terrain, orient_feet, place_on_ground, sample_locations
from toolkit.policy.env import CharacterEnv
from toolkit.interfaces.simulator import Watch
from toolkit.motion import rotations as rot

START_KINDS = ("clip", "fallen", "standing")  #: ``info["start_kind"]`` codes 0, 1, 2
LOOKAHEAD = np.array([0.0, 0.1, 0.2, 0.3])  #: s, curve targets in the state (003 §3.3.2)


@dataclasses.dataclass
class GetupSpec(_C):
    """What a getup environment runs from, as plain picklable data: every setting of the
    task's ``GetupConfig`` (inherited, so each is declared once, there, with its default and source),
    plus the values the task resolves from them (below; ``toolkit.policy.spec.spec_of``)."""

    curves: list = dataclasses.field(default_factory=list)  # FeatureCurve.to_dict() each
    fallen: list = dataclasses.field(default_factory=list)  # initial.fallen_states() entries
    reward: dict = dataclasses.field(default_factory=dict)  # {"terms": {name: params}}
    terrain: dict = dataclasses.field(default_factory=dict)  # resolved: TerrainSpec.to_dict(); {}: flat only
    sim: dict = dataclasses.field(default_factory=dict)
    action: dict = dataclasses.field(default_factory=lambda: {"name": "raw"})


def joint_rotations(q: np.ndarray) -> np.ndarray:
    """Each internal joint's rotation relative to its parent ``(12, 4)`` (x, y, z, w); revolute
    joints as the rotation about their axis."""
    from toolkit.motion.skeletons import HUMANOID, SPHERICAL

    joints = np.asarray(q, dtype=np.float64)[7:]
    out = []
    for j, s in zip(HUMANOID.joints, HUMANOID.q_slices.values()):
        if j.kind == SPHERICAL:
            out.append(rot.quat_normalize(joints[s]))
        else:
            out.append(rot.quat_from_axis_angle(np.array(j.axis, dtype=np.float64), float(joints[s.start])))
    return np.stack(out)


def joint_layout() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where ``joint_rotations`` reads each joint in ``q``: start indices ``(12,)`` (past the 7
    root coordinates), spherical flags ``(12,)`` and revolute axes ``(12, 3)`` (zero for a
    spherical joint), for ``kernels.joint_rotations``."""
    from toolkit.motion.skeletons import HUMANOID, SPHERICAL

    starts = np.array([7 + s.start for s in HUMANOID.q_slices.values()], dtype=np.int64)
    spherical = np.array([j.kind == SPHERICAL for j in HUMANOID.joints])
    axes = np.array([(0.0, 0.0, 0.0) if j.kind == SPHERICAL else tuple(j.axis) for j in HUMANOID.joints],
                    dtype=np.float64)
    return starts, spherical, axes


class GetupEnv(CharacterEnv):
    """Get up from a fallen state tracking the height and torso-angle curves (003)."""

    #: closer and from above: a lying character fills a frame (ours; the side view at 3 m shows a speck)
    CAMERA = {"distance": 2.4, "yaw": 30.0, "pitch": -28.0}

    def setup(self) -> None:
        spec = self.spec_
        self.curves = [FeatureCurve.from_dict(c) for c in spec.curves]
        if not self.curves:
            raise ValueError("getup: no feature curves")
        self.curve_starts = np.array([c.start for c in self.curves])
        self.control_hz = float(self.sim.control_hz)
        self.dt = 1.0 / self.control_hz
        self._m = self._lv = self._ahead = None  # this state's measurements, link velocities, targets
        self.torso_links = F.torso_links(self.sim)  # resolved once: measured every step
        self.head_link = self.sim.link_index(F.HEAD)
        self.terms = self.load_terms((spec.reward or {}).get("terms"))
        self.natural = set(spec.natural_terms)
        q_stand, qd_stand = clip_pose("getup_facedown", False, frame=-1)
        rest = np.zeros_like(qd_stand)
        if spec.stand_pose == "symmetric":  # the right leg mirrors the left, soles flat (ours)
            q_stand = symmetric_legs(q_stand)
            self.sim.reset(q_stand, rest)
            q_stand = lift_to_ground(orient_feet(self.sim, q_stand, rest))
        self.stand_state = (q_stand, rest)
        self.neutral = joint_rotations(q_stand)  # q̂ of eq 9: the standing pose (task.stand_pose)
        self._joints = joint_layout()
        self._clip_starts: dict[tuple, tuple] = {}
        self.terrain_level = 0  # highest unlocked region, set by the terrain curriculum (003 §5.4)
        self.rsi_from = float(spec.rsi_from)  # starts inside the clip from this fraction of it on (reverse.py)
        self.region = 0  # the episode's region
        self.tspec = TerrainSpec.from_dict(spec.terrain) if spec.terrain else None
        self.ground_bodies = {int(self.sim.ground)}
        if self.tspec is not None:
            self.ground_bodies.update(add_terrain(self.sim, self.tspec, self.sim.friction))
        self.fallen_by_region: dict[int, list[int]] = {}
        for i, st in enumerate(spec.fallen):
            self.fallen_by_region.setdefault(int(st.get("region", 0)), []).append(i)
        self._begin(0, "clip" if self.curves[0].clip else "standing", None)

    # ------------------------------------------------------------------ episodes
    def _clip_start(self, c: FeatureCurve, at: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """The clip's state ``at`` s on the curve's clock (0: its first pose, memoised)."""
        if at > 0.0:
            return clip_state_at(c.clip, c.mirrored, at, c.duration)
        key = (c.clip, c.mirrored)
        if key not in self._clip_starts:
            self._clip_starts[key] = clip_pose(c.clip, c.mirrored, frame=0)
        return self._clip_starts[key]

    def _begin(self, curve: int, kind: str, fallen: Optional[int], where: Optional[np.ndarray] = None,
               at: float = 0.0, noise: float = 0.0, noise_rng: Optional[np.random.Generator] = None) -> None:
        c = self.curves[curve]
        if kind == "clip":
            q, qd = self._clip_start(c, at)
            if noise > 0.0:  # a perturbed clip start, resting on the ground again
                q = lift_to_ground(perturb_joints(q, noise_rng, noise))
        elif kind == "fallen":
            st = self.spec_.fallen[fallen]
            q, qd = np.asarray(st["q"], float), np.asarray(st["qd"], float)
        else:
            q, qd = self.stand_state
        if where is not None:  # a standing start on irregular terrain, feet to the slope (003 §5.2)
            q = orient_feet(self.sim, place_on_ground(self.sim, q, qd, where), qd)
            place_on_ground(self.sim, q, qd, where)
        else:
            self.sim.reset(np.array(q), np.array(qd))
        self.action_space_.reset(None)
        if hasattr(self.action_space_, "use_clip"):  # a feed-forward under the policy: this curve's clip (ours)
            from jt_tasks.getup.curves import load_getup_clip

            self._ff_clip = load_getup_clip(c.clip, c.mirrored)
            self.action_space_.use_clip(self._ff_clip, name=c.clip)
            # ffc_hold=stance: the move to the stance starts as the clip ends (a standing start: done)
            self._stance_t0 = c.duration - (float(self.spec_.ffc_blend) if kind == "standing" else 0.0)
        self.curve_index, self.curve, self.start_kind = curve, c, kind
        # the curve's clock at the start: standing s = 1; a clip start inside the clip (rsi) its time
        self.t_offset = c.duration if kind == "standing" else (float(at) if kind == "clip" else 0.0)
        self.start_time = self.t_offset if kind == "clip" else 0.0
        self.t_end = c.duration + float(self.spec_.t_stand)
        self.watch = Watch(time_limit=self.t_end - self.t_offset, time_limit_outcome="truncate",
                           time_limit_reason="time limit")
        self.low_t = self.head_t = self.stand_t = 0.0
        self.got_up = False
        self.rise_t = math.nan  # s from the start until the neck first reaches the standing height
        self.log: list[dict[str, float]] = []
        self.last_action = np.zeros(self.action_space.shape, dtype=np.float64)
        self._prev_links = None
        self._m = self._lv = self._ahead = None
        self.curve_end = c.end  # p(1), read by every step's reward record
        self.supine = bool(self.measure()["features"][2] < math.pi / 2)
        self.head_down_at_start = self._head_contact() or self._head_height() < 0.15

    def _head_contact(self) -> bool:
        """The head link touches the ground plane or the terrain."""
        return any(link == self.head_link and body in self.ground_bodies for body, link in self.sim.contacts())

    def _head_height(self) -> float:
        lo, _ = self.sim.aabb(self.head_link)
        return float(lo[1]) - float(np.min(self.measure()["ground"]))

    @property
    def t(self) -> float:
        """Episode time on the curve's clock (s; a standing start begins at ``T``)."""
        return float(self.sim.time) + self.t_offset

    def start(self, options: Optional[dict]) -> dict:
        """A new episode (003 §5.2, §5.4): a region among the unlocked ``0..terrain_level`` (all keep
        being visited), then on flat ground a standing, rag-doll or clip start, on irregular ground a
        standing start at a random location or a rag-doll state dropped there (clip poses are used on
        flat terrain only, 003 §5.2). A clip start begins at a random time of the clip with
        probability ``rsi`` and is perturbed by ``start_noise`` rad. Options: ``kind``, ``curve``
        (index or name), ``fallen`` (index into the spec's states), ``region``, ``at`` (s into a clip
        start), ``noise`` and ``noise_seed`` (a clip start perturbed by ``noise`` rad, seeded)."""
        spec, rng = self.spec_, self.np_random
        opts = dict(options or {})
        kind, curve, fallen, region = opts.get("kind"), opts.get("curve"), opts.get("fallen"), opts.get("region")
        if isinstance(curve, str):
            names = [c.name for c in self.curves]
            curve = names.index(curve) if curve in names else None
        top = min(int(self.terrain_level), self.tspec.n_regions - 1) if self.tspec is not None else 0
        if fallen is not None:
            region = int(spec.fallen[int(fallen)].get("region", 0))
        elif region is None:
            region = int(rng.integers(top + 1))
        region = int(region) if self.tspec is not None else 0
        pool_fallen = self.fallen_by_region.get(region, [])
        with_clip = [i for i, c in enumerate(self.curves) if c.clip] if region == 0 else []
        if kind is None:
            u = float(rng.random())
            if u < spec.p_standing:
                kind = "standing"
            elif (u < spec.p_standing + spec.p_fallen or region > 0) and pool_fallen:
                kind = "fallen"
            else:
                kind = "clip" if with_clip else ("fallen" if pool_fallen else "standing")
        if kind == "fallen" and fallen is None and not pool_fallen:
            kind = "clip" if with_clip else "standing"
        if kind == "fallen":
            fallen = int(pool_fallen[int(rng.integers(len(pool_fallen)))]) if fallen is None else int(fallen)
            if curve is None:
                st = spec.fallen[fallen]
                self.sim.reset(np.asarray(st["q"], float), np.asarray(st["qd"], float))
                self._m = self._lv = None
                angles = self._measure_now()["features"]
                curve = pick_curve(angles, self.curve_starts, rng, spec.curve_match_deg)
        if curve is None:
            pool = with_clip if kind == "clip" else list(range(len(self.curves)))
            curve = int(pool[int(rng.integers(len(pool)))])
        if kind == "clip" and (not self.curves[int(curve)].clip or region > 0):
            kind = "standing"
        where = None
        if kind == "standing" and region > 0:
            where = sample_locations(self.tspec, region, 1, rng)[0]
        at, noise, noise_rng = 0.0, 0.0, None
        if kind == "clip":  # no draw at the defaults (rsi = start_noise = 0): the same episodes as before
            at = float(opts.get("at", 0.0) or 0.0)
            if "at" not in opts and spec.rsi > 0.0 and float(rng.random()) < spec.rsi:
                duration = self.curves[int(curve)].duration
                at = float(rng.uniform(float(self.rsi_from) * duration, duration))
            noise = float(opts.get("noise", spec.start_noise) or 0.0)
            if noise > 0.0:
                seed = opts.get("noise_seed")
                noise_rng = rng if seed is None else np.random.default_rng(int(seed))
        self.region = region
        self._begin(int(curve), kind, fallen, where, at, noise, noise_rng)
        out = {"curve": float(self.curve_index), "start_kind": float(START_KINDS.index(kind)),
               "terrain_level": float(self.region), "unlocked_level": float(self.terrain_level)}
        if self.start_time > 0.0:  # a clip start inside the clip (rsi)
            out["start_time"] = float(self.start_time)
        return out

    # ------------------------------------------------------------------ measurements
    def _measure_now(self) -> dict[str, Any]:
        return F.measure(self.sim, self.spec_.heightmap_n, self.spec_.heightmap_spacing, links=self.torso_links)

    def measure(self) -> dict[str, Any]:
        """Features, heading and height map of the current state (cached until the next step)."""
        if self._m is None:
            self._m = self._measure_now()
        return self._m

    def state_changed(self, prev_links: Optional[tuple] = None) -> None:
        """Forget this step's measurements, link velocities and curve targets after the state or
        the clock was set from outside a step (a kinematic replay); ``prev_links`` are the link
        states the next velocities difference against (None: zero velocities)."""
        self._prev_links = prev_links
        self._m = self._lv = self._ahead = None

    def link_velocities(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Link positions, orientations, angular and linear velocities ``(16, ·)`` (world), the
        velocities by finite differences over the last control step (cached until the next step:
        the reward's record and the observation both read them; read-only, not copies)."""
        if self._lv is None:
            pos, orn = self.sim.link_states()
            w, v = np.zeros_like(pos), np.zeros_like(pos)
            if self._prev_links is not None:
                p0, o0 = self._prev_links
                kernels.link_velocities(pos, orn, p0, o0, self.dt, w, v)
            for a in (pos, orn, w, v):
                a.flags.writeable = False
            self._lv = pos, orn, w, v
        return self._lv

    def targets(self, t: Any) -> np.ndarray:
        """Curve targets ``(…, 3)`` at episode time(s) ``t``."""
        return self.curve(t)

    def targets_ahead(self) -> np.ndarray:
        """Curve targets ``(4, 3)`` now and ``LOOKAHEAD`` s ahead (cached until the next step: the
        reward record reads the first row, the observation all four)."""
        if self._ahead is None:
            self._ahead = self.targets(self.t + LOOKAHEAD)
            self._ahead.flags.writeable = False
        return self._ahead

    def _stance_clip(self, clip: Any) -> Any:
        """A two-frame clip from ``clip``'s last frame to the standing pose in ``ffc_blend`` s (memoised)."""
        import dataclasses as dc

        memo = self.__dict__.setdefault("_stance_clips", {})
        if id(clip) not in memo:
            q = self.stand_state[0]
            memo[id(clip)] = dc.replace(
                clip, name=f"{clip.name}_to_stance", times=np.array([0.0, float(self.spec_.ffc_blend)]),
                root_pos=np.stack([clip.root_pos[-1], q[:3]]), root_rot=np.stack([clip.root_rot[-1], q[3:7]]),
                joints=np.stack([clip.joints[-1], q[7:]]), loop=False, source="")
        return memo[id(clip)]

    def clip_phase(self, t: float) -> float:
        """The episode clip's phase ``[0, 1]`` at curve time ``t`` s (the clip's time scaled to the
        curve's ``T``; 1, its last frame, held through the standing phase)."""
        return min(max(float(t) / float(self.curve.duration), 0.0), 1.0)

    def feedforward_time(self) -> float:
        """Curve time (s) of the feed-forward target: now plus ``ffc_lead`` control steps."""
        return self.t + float(self.spec_.ffc_lead) * self.dt

    # ------------------------------------------------------------------ gymnasium hooks
    def pd_targets(self, action: np.ndarray) -> np.ndarray:
        if hasattr(self.action_space_, "set_condition"):  # C-VAE: c = the curves now (003 §3.4)
            self.action_space_.set_condition(self.targets(self.t))
        if hasattr(self.action_space_, "set_phase"):  # feed-forward: the clip's pose at the curve's clock (ours)
            t = self.feedforward_time()
            if self.spec_.ffc_hold == "stance" and t >= self._stance_t0 and t >= self.curve.duration:
                self.action_space_.use_clip(self._stance_clip(self._ff_clip))  # then on to the stance
                self.action_space_.set_phase(min((t - self._stance_t0) / float(self.spec_.ffc_blend), 1.0))
            else:
                self.action_space_.use_clip(self._ff_clip)
                self.action_space_.set_phase(self.clip_phase(t))
        # the links now, as the observation of this state read them (the same state: no new query)
        self._prev_links = self._lv[:2] if self._lv is not None else self.sim.link_states()
        self._lv = None
        self.last_action = np.asarray(action, dtype=np.float64).copy()
        return super().pd_targets(action)

    def pd_velocity_targets(self) -> Optional[np.ndarray]:
        """With a feed-forward and ``ffc_velocity``: the clip's joint velocities ``(n_v,)`` at the
        feed-forward's time, scaled to the curve's clock (root entries and the held last frame 0)."""
        if not (self.spec_.ffc_velocity and hasattr(self.action_space_, "set_phase")):
            return None
        phase = self.clip_phase(self.feedforward_time())
        if phase >= 1.0:
            return np.zeros(self.sim.model.n_v)
        from jt_tasks.getup.curves import load_getup_clip
        from jt_tasks.takeoff.state import reference_state

        clip = load_getup_clip(self.curve.clip, self.curve.mirrored)
        length = float(clip.times[-1] - clip.times[0])
        tc = float(clip.times[0]) + phase * length
        tc = min(max(tc, float(clip.times[0]) + 1.0 / 120.0), float(clip.times[-1]) - 1.0 / 120.0)
        jv = np.asarray(reference_state(clip, tc)[5], dtype=np.float64) * (length / float(self.curve.duration))
        return np.concatenate([np.zeros(6), jv])

    def observe(self) -> np.ndarray:
        m = self.measure()
        pos, orn, w, v = self.link_velocities()
        n = pos.shape[0]
        prev = getattr(self.action_space_, "filtered", None)
        prev = self.last_action if prev is None else prev
        feats, hmap = m["features"], m["heightmap"]
        out = np.empty(13 * n + feats.size + hmap.size + 3 * len(LOOKAHEAD) + np.size(prev))
        kernels.observe_links(pos, orn, w, v, float(m["yaw"]), out)  # orientations, positions, w, v
        k = 13 * n
        for x in (feats, hmap, self.targets_ahead(), prev):
            x = np.asarray(x, dtype=np.float64).reshape(-1)
            out[k:k + x.size] = x
            k += x.size
        return out.astype(np.float32)

    def record_now(self) -> dict[str, Any]:
        """The reward terms' record of the current state."""
        m = self.measure()
        q, _ = self.sim.state()
        _, _, w, _ = self.link_velocities()
        tgt, end = self.targets_ahead()[0], self.curve_end
        h, tx, tz = (float(x) for x in m["features"])
        return {"h": h, "theta_x": tx, "theta_z": tz, "target_h": float(tgt[0]), "target_theta_x": float(tgt[1]),
                "target_theta_z": float(tgt[2]), "target_h_end": float(end[0]), "link_ang_vel": w,
                "joint_rotations": self._joint_rotations(q), "neutral_rotations": self.neutral,
                "naturalness": float(min(max(self.penalty, 0.0), 1.0))}

    def _joint_rotations(self, q: np.ndarray) -> np.ndarray:
        """``joint_rotations(q)`` compiled ``(12, 4)``."""
        out = np.empty((len(self._joints[0]), 4))
        kernels.joint_rotations(np.asarray(q, dtype=np.float64), *self._joints, out)
        return out

    def finish_step(self, rec: dict[str, Any]) -> tuple[float, bool, bool, dict]:
        self._m = self._lv = self._ahead = None
        spec = self.spec_
        if rec["failed"]:
            return 0.0, True, False, self._final(self.failure(rec), False)
        record = self.record_now()
        values = {k: float(term(record)) for k, term in self.terms.items()}
        r_task = math.prod(v for k, v in values.items() if k not in self.natural)
        r = r_task * math.prod(v for k, v in values.items() if k in self.natural)
        self.low_t = self.low_t + self.dt if r_task < spec.r_task_min else 0.0
        grace = spec.head_grace if self.head_down_at_start and self.start_kind != "standing" else 0.0
        head = self._head_contact()
        self.head_t = self.head_t + self.dt if head and self.sim.time > grace else 0.0
        standing = record["h"] >= spec.success_height * record["target_h_end"]
        self.stand_t = self.stand_t + self.dt if standing else 0.0
        if standing and not self.got_up:
            self.rise_t = float(self.sim.time)
        self.got_up = self.got_up or standing
        self.log.append({"r": r, "r_task": r_task, **{f"r_{k}": v for k, v in values.items()},
                         "h": record["h"], "theta_x": record["theta_x"], "theta_z": record["theta_z"],
                         "target_h": record["target_h"], "target_theta_x": record["target_theta_x"],
                         "target_theta_z": record["target_theta_z"], "head_contact": float(head)})
        reason = ""
        if self.low_t > spec.sustain + 1e-9:
            reason = f"r_task < {spec.r_task_min:g}"
        elif self.head_t > spec.sustain + 1e-9:
            reason = "head on the floor"
        if reason:
            return r, True, False, self._final(reason, False)
        if rec["outcome"] == "truncate":
            return r, False, True, self._final("time limit", True)
        return r, False, False, {}

    def _final(self, reason: str, reached_end: bool) -> dict[str, Any]:
        spec = self.spec_
        success = reached_end and self.stand_t >= spec.success_window - 1e-9
        standing = self.start_kind == "standing"
        info: dict[str, Any] = {"reason": reason, "success": float(success and not standing),
                                "early": float(not reached_end),
                                "got_up": float(self.got_up and not standing),
                                "standing_success": float(success and standing),
                                "start_kind": float(START_KINDS.index(self.start_kind)),
                                "curve": float(self.curve_index), "terrain_level": float(self.region),
                                "unlocked_level": float(self.terrain_level),
                                "episode_time": float(self.sim.time), "steps": float(len(self.log)),
                                "time_to_rise": float(self.rise_t) if not standing else math.nan}
        if self.start_time > 0.0:  # a clip start inside the clip (rsi): not a get-up from the ground
            info["start_time"] = float(self.start_time)
            info["start_frac"] = float(self.start_time / self.curve.duration)  # reverse.StartWindow reads it
        if self.log:
            for k in self.log[0]:
                if k.startswith("r"):
                    info[f"{k}_mean"] = float(np.mean([row[k] for row in self.log]))
            info["task_return_rate"] = float(np.sum([row["r_task"] for row in self.log]) /
                                             max(1.0, (self.t_end - self.t_offset) * self.control_hz))
        return info
