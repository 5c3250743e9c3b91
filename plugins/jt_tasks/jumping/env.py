"""The jump environment (``gymnasium.Env``): from a take-off state over a bar / obstacle onto a mat.

One episode (``000`` §6.1): reset to the take-off state (``takeoff``) in front of the suite
(``scene``); each ``step`` maps the action to PD targets (the action space plugin), then the
simulator runs ``round(sim_hz / control_hz)`` substeps, checking the episode's rules
(``Watch``) after each:

* failure (terminated, reward = product of the terms = 0 through ``task_complete``): any body part
  touches the wall / obstacle, any part other than the take-off foot touches the ground, the
  simulator fails (NaN, exploding), or the jump has not succeeded ``time_limit`` s (2 s) after
  take-off;
* success (terminated): the character touches the mat with every part at least ``safe_margin``
  (20 cm) from the wall / obstacle.

The reward is sparse: 0 on every step but the last, where it is the product of the configured
terms (``000`` eqs 2, 15, 16) on the episode record ``success``, ``root_ang_vel_mean`` (mean root
angular speed over the control steps), ``head_first_landing`` (the neck/head link was among the
first links to touch the mat), ``naturalness`` (the action space's ``penalty()`` averaged over the
episode), ``feature`` and ``policy_features`` (Stage 2). Every term value is in the final ``info``
as ``r_<term>``, with ``feature_angle`` (Stage-1 feature), ``crossed``, ``success``.

The environment attributes ``bar_height`` / ``obstacle_width`` (rebuilds the suite at the next
reset), ``control_hz`` and ``c_offset`` are what the curricula set (``set_wrapper_attr``).

Observation ``(obs_dim,)`` float32, in the suite frame (normal, up, along): root height, root
position relative to the feature plane (normal and along components), root orientation (6D),
root linear and angular velocity, internal joint positions (quaternions / angles) and velocities,
link centres of mass relative to the root, the difficulty value, time since take-off / limit.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Optional

import numpy as np

from jt_tasks.jumping.features import CrossingTracker, suite_orientation
from jt_tasks.jumping.scene import Suite, SuiteSpec
from jt_tasks.jumping.config import JumpConfig as _C
from toolkit.policy.env import CharacterEnv
from jt_tasks.takeoff.state import FOOT_LINKS, takeoff_state
from toolkit.interfaces.simulator import ContactRule, Watch

HEAD = "neck"  #: the humanoid's link that carries the head (by name; ``setup`` resolves it)


@dataclasses.dataclass
class EnvSpec(_C):
    """What a jump environment runs from, as plain picklable data: every setting of the
    task's ``JumpConfig`` (inherited, so each is declared once, there, with its default and source),
    plus the values the task resolves from them (below; ``toolkit.policy.spec.spec_of``)."""

    kind: str = "highjump"  # highjump | obstacle
    features: dict = dataclasses.field(default_factory=dict)  # take-off features by name
    suite: SuiteSpec = dataclasses.field(default_factory=SuiteSpec)
    takeoff_file: str = ""  # a run-up's takeoff_state.h5 to start from instead of the clip frame (takeoff_source)
    foot_clearance: float = 0.002  # m between the take-off foot and the ground at reset (ours)
    control_hz: float = 10.0  # initial control rate (the curriculum changes it)
    sim: dict = dataclasses.field(default_factory=dict)  # {"sim": ..., "spd": ..., "character": ...}
    action: dict = dataclasses.field(default_factory=lambda: {"name": "raw"})
    reward_terms: dict = dataclasses.field(default_factory=dict)  # {term: params}
    policy_features: list = dataclasses.field(default_factory=list)  # Stage 2: f_i of earlier policies


class JumpEnv(CharacterEnv):
    """High / obstacle / long jump from a take-off state (000 §6.1), sparse product reward."""

    #: distance (m) and pitch (deg) of the view along the bar (``render_frame``)
    CAMERA = {"distance": 3.5, "pitch": -8.0}

    def render_frame(self, width: int, height: int, mask: bool = False) -> Any:
        """RGB frame ``(height, width, 3)`` uint8 looking along the bar (its wall edge-on, below the
        athlete as the CoM crosses its plane): the side view of a clearance, as ``000`` Fig. 7;
        with ``mask``, also the character's pixels."""
        from toolkit.render import Camera

        along = self.suite.rotation()[:, 2]
        yaw = math.degrees(math.atan2(float(along[0]), float(along[2])))
        return self.sim.render(width, height, Camera(yaw=yaw, **self.CAMERA), mask=mask)

    # ------------------------------------------------------------------ set-up (scene, initial state)
    def setup(self) -> None:
        spec = self.spec_
        self.foot_link = self.sim.link_index(FOOT_LINKS[spec.foot])
        self.head_link = self.sim.link_index(HEAD)
        self.terms = self.load_terms(spec.reward_terms)
        self.suite = Suite(self.sim, spec.suite)
        feats = {k: float(v) for k, v in spec.features.items() if k != "alpha"}
        if spec.takeoff_file:
            from jt_tasks.takeoff import source as takeoff_source

            self.takeoff = takeoff_source.load(spec.takeoff_file, spec.foot, spec.v_y)
        else:
            self.takeoff = takeoff_state(feats, spec.clip, spec.foot, spec.omega_y, v_y=spec.v_y)
        self._q0, self._qd0 = self._place(self.takeoff.q, self.takeoff.qd)
        if spec.suite.kind == "highjump":  # the wall where the run crosses (the bar plane is fixed)
            self.suite.update(centre_along=self.suite.crossing_along(self._qd0[:3]))
        self.control_hz = float(spec.control_hz)
        self._pending = dict(bar_height=spec.suite.bar_height, obstacle_width=spec.suite.obstacle_width)
        self.tracker = CrossingTracker()
        self._reset_episode()

    def _rules(self) -> Watch:
        """Ends a jump: the wall / obstacle touched, the ground touched by anything but the take-off
        foot, a landing on the mat clear of the wall (success), the time limit; the first touch of
        the mat is noted (head-first landing), CoM and root are recorded for the crossing."""
        spec, suite = self.spec_, self.suite
        rules = []
        if suite.barrier_id >= 0:
            rules.append(ContactRule(suite.barrier_id, "fail", "touched the bar"))
        rules += [ContactRule(self.sim.ground, "fail", "touched the ground", except_links=(self.foot_link,)),
                  ContactRule(suite.mat_id, "success", "success", clear_of=suite.barrier_id,
                              margin=spec.safe_margin)]
        return Watch(rules=tuple(rules), touches=(suite.mat_id,), record=("time", "com", "root"),
                     time_limit=spec.time_limit, check_every=spec.check_every)

    # ------------------------------------------------------------------ curriculum attributes
    @property
    def bar_height(self) -> float:
        return float(self._pending["bar_height"])

    @bar_height.setter
    def bar_height(self, value: float) -> None:
        self._pending["bar_height"] = float(value)

    @property
    def obstacle_width(self) -> float:
        return float(self._pending["obstacle_width"])

    @obstacle_width.setter
    def obstacle_width(self, value: float) -> None:
        self._pending["obstacle_width"] = float(value)

    @property
    def c_offset(self) -> float:
        return float(getattr(self.action_space_, "c_offset", math.nan))

    @c_offset.setter
    def c_offset(self, value: float) -> None:
        if hasattr(self.action_space_, "set_c_offset"):
            self.action_space_.set_c_offset(float(value))

    @property
    def substeps(self) -> int:
        """Simulation substeps per control step: ``round(sim_hz / control_hz)`` (at least 1)."""
        return max(1, int(round(self.sim_hz / float(self.control_hz))))

    def substeps_now(self) -> int:
        return self.substeps

    @property
    def difficulty(self) -> float:
        """The curriculum's z: bar height (high jump) or obstacle width."""
        s = self.suite.spec
        return s.bar_height if s.kind == "highjump" else s.obstacle_width

    # ------------------------------------------------------------------ helpers
    def _place(self, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Lift/lower the state so that the take-off foot is ``foot_clearance`` above the ground."""
        q = q.copy()
        self.sim.reset(q, qd)
        foot_min = self.sim.aabb(self.foot_link)[0][1]
        q[1] += self.spec_.foot_clearance - foot_min
        return q, qd.copy()

    def _com_and_links(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        pos, orn = self.sim.link_states()
        com = self.masses @ pos / self.masses.sum()
        return com, pos, orn[0]

    def _reset_episode(self) -> None:
        spec = self.suite.spec
        if spec.kind == "highjump":
            self.suite.update(bar_height=self._pending["bar_height"])
        else:
            self.suite.update(obstacle_width=self._pending["obstacle_width"])
        self.watch = self._rules()
        self.sim.reset(self._q0, self._qd0)
        self.action_space_.reset(None)
        self.tracker.reset()
        self.t = 0.0
        self._ang_speeds: list[float] = []
        self._penalties: list[float] = []
        self.landed = False
        self.head_first = False
        com, _, orn = self._com_and_links()
        self.tracker.update(0.0, float(self.suite.past(com)), orn)

    def observe(self) -> np.ndarray:
        q, qd = self.sim.state()
        com, links, orn = self._com_and_links()
        R = self.suite.rotation()
        root = q[:3]
        from toolkit.motion.rotations import quat_to_matrix

        m = R.T @ quat_to_matrix(q[3:7])
        rel = (links[1:] - root) @ R
        parts = [
            [root[1], float(self.suite.past(root)), float(self.suite.along_offset(root))],
            m[:, :2].T.reshape(-1), R.T @ qd[:3], R.T @ qd[3:6], q[7:], qd[6:], rel.reshape(-1),
            [self.difficulty, self.t / self.spec_.time_limit],
        ]
        return self.flat(parts)

    # ------------------------------------------------------------------ episode
    def start(self, options: Optional[dict]) -> dict:
        self._reset_episode()
        return {}

    def finish_step(self, rec: dict[str, Any]) -> tuple[float, bool, bool, dict]:
        self._penalties.append(self.penalty)
        self.t = float(rec["time"])
        smp = rec["samples"]
        if len(smp["time"]):
            past = self.suite.past(smp["com"])
            if self.tracker.update_many(smp["time"], past, smp["root"][:, 3:7]) \
                    and self.suite.beside(smp["com"][self.tracker.hit_index]):
                self.tracker.reset()  # round the end of the wall: no crossing, no feature
                what = "bar" if self.suite.spec.kind == "highjump" else "obstacle"
                return self._finish(False, f"passed beside the {what}")
        mat = rec["touched"].get(self.suite.mat_id)
        if mat is not None and not self.landed:
            self.landed, self.head_first = True, self.head_link in mat
        status, reason = rec["outcome"], self.failure(rec) or rec["reason"]
        w = rec["qd"][3:6]  # the step record's state is the simulator's state now
        self._ang_speeds.append(math.sqrt(w.dot(w)))  # np.linalg.norm's own sum, without its overhead
        if not status:
            return 0.0, False, False, {}
        return self._finish(status == "success", "" if status == "success" else reason)

    def _finish(self, success: bool, reason: str) -> tuple[float, bool, bool, dict]:
        if success and not self.tracker.crossed:  # landed reaching over: the feature at the landing
            self.tracker.land(self.t, self._com_and_links()[2])
        record = self.episode_record(success)
        values = {name: float(term(record)) for name, term in self.terms.items()}
        reward = math.prod(values.values()) if values else float(success)
        info: dict[str, Any] = {f"r_{k}": v for k, v in values.items()}
        info.update(success=float(success), crossed=float(self.tracker.crossed),
                    feature_angle=float(self.tracker.stage1()), bar_height=float(self.difficulty),
                    naturalness=record["naturalness"], root_ang_vel_mean=record["root_ang_vel_mean"],
                    head_first_landing=float(record["head_first_landing"]), episode_time=self.t,
                    control_hz=float(self.control_hz), reason=reason or "success",
                    crossed_at_landing=float(self.tracker.at_landing))
        return float(reward), True, False, info

    def episode_record(self, success: bool) -> dict[str, Any]:
        """The end-of-episode record the reward terms read."""
        return {
            "success": bool(success),
            "root_ang_vel_mean": float(np.mean(self._ang_speeds)) if self._ang_speeds else 0.0,
            "head_first_landing": bool(self.head_first),
            "naturalness": float(np.mean(self._penalties)) if self._penalties else 1.0,
            # not crossed: the root orientation now (the closest approach so far), finite as the
            # novelty term needs (a zero quaternion made r_novelty NaN; the product is 0 anyway)
            "feature": self.tracker.stage2(self.suite.rotation()) if self.tracker.crossed
            else suite_orientation(self._com_and_links()[2], self.suite.rotation()),
            "policy_features": np.asarray(self.spec_.policy_features, dtype=float).reshape(-1, 4)
            if len(self.spec_.policy_features) else np.zeros((0, 4)),
        }
