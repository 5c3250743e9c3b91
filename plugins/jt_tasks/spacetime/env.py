"""The spacetime-bounds environment (``gymnasium.Env``): track a clip inside its bounds (``002``).

* Reference state initialisation: an episode starts in the reference state at a phase drawn
  uniformly from ``[0, 1)`` with the env's ``np_random`` (``reset(options={"phase": φ})`` or the
  spec's ``init_phase`` fixes it), clip time ``t0 = φ T``. Once the learner has set the attribute
  ``start_sampling`` (``jt_tasks.spacetime.sampling``), the start segment is drawn with its eq 11
  probabilities ``probs`` (002 §4.3.1) and the phase uniformly inside it; with the evolution's
  buffers (002 §4.3.2 eq 12) present, a share ``share`` of starts is a buffer state of that
  segment instead (uniform over its ``count`` states; root x, z placed at the reference's).
  ``visit_state()`` reports each state (``[phase, q with root x, z = 0, qd]``) to PPO when the
  spec's ``sampling["evolution"]`` is on.
* Action (``action=ffc_fbc``, 002 §4.2): the PD target is the reference pose at the control
  step's phase (the action space's feed-forward controller, fed the phase here) plus the policy's
  correction; held over the control step's substeps (600 Hz / 30 Hz).
* ``termination: bounds`` (002 §3.2 eq 2, §5.1): after every control step the 22-channel difference
  between the character and the reference at the same clip time (``bounds.difference``) is
  compared with the widths; a channel out of bounds ends the episode with reward 0; otherwise the
  reward is 1 times the product of the style terms (none: 1). No contact rule.
* ``termination: contact`` (the DeepMimic baseline of 002 Table 1): a ground contact of a link not
  allowed for the clip ends the episode with reward 0; otherwise DeepMimic's imitation reward
  (``jt_tasks.runup.reward.imitation_terms``).
* ``mix = w_s`` (either arm): the reward is eq 13's ``(1 − w_s) r_imitation + w_s r_style``
  (002 §5.3.1, Table 2) instead of the style product / the imitation reward.
* An episode is truncated (bootstrapped) at ``time_limit`` (20 s, 002 §5.1), or, for a
  non-looping clip, ``hold_s`` after the clip's end (the clip holds its last frame).
* Evaluation (``reset(options={"evaluate": True})``, 002 Table 1): bounds off, only a forbidden
  ground contact (``eval_allowed``) ends the episode, truncated at ``eval_time_limit``; reward 1
  per control step; ``info["survival_s"]`` is the episode's length.

Observation ``(obs_dim,)`` float32 (after the authors' 197-D one, research notes): the clip phase,
root height, the base's and every link's centre of mass relative to the ground-projected root and
their orientations, in the heading frame, the root's linear and angular velocity in the heading
frame and the joint velocities (148-D), or with ``velocities=links`` every link's linear and
angular velocity in the heading frame (210-D: 002 §4.1 and the authors' 197-D state, plus the
massless base's row).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Optional

import numpy as np

from toolkit.policy.env import CharacterEnv
from jt_tasks.spacetime import clips
from jt_tasks.spacetime.config import SpacetimeConfig as _C
from jt_tasks.spacetime import bounds as bd
from jt_tasks.spacetime.reference import SpacetimeReference, end_effector_links, heading_frame, heading_quat
from toolkit.interfaces.simulator import ContactRule, Watch
from toolkit.motion import rotations as rot

_NO_LINKS = np.zeros((0, 3))  #: observe's link velocities with task.velocities=joints


@dataclasses.dataclass
class SpacetimeSpec(_C):
    """What a spacetime environment runs from, as plain picklable data: every setting of the
    task's ``SpacetimeConfig`` (inherited, so each is declared once, there, with its default and source),
    plus the values the task resolves from them (below; ``toolkit.policy.spec.spec_of``)."""

    widths: list = dataclasses.field(default_factory=list)  # (n_channels,), inf = off; [] = 002 §5.1
    width_table: list = dataclasses.field(default_factory=list)  # (K, n_channels) over phase [0, 1]; [] = widths
    train_allowed: Optional[tuple] = None  # link indices allowed on the ground in the contact arm; None: per clip
    eval_allowed: Optional[tuple] = None  # ... in the evaluation; None: per clip (clips.allowed_links)
    sampling: dict = dataclasses.field(default_factory=dict)  # {"evolution": bool} (sampling.SamplingParams)
    sim: dict = dataclasses.field(default_factory=dict)
    action: dict = dataclasses.field(default_factory=lambda: {"name": "ffc_fbc"})


class SpacetimeEnv(CharacterEnv):
    """Track a reference clip inside its spacetime bounds (002 §3.2), or the DeepMimic baseline."""

    start_sampling: Optional[dict] = None
    """Eq 11 / eq 12 start distribution set by the learner (``StartSampler.payload``); None: uniform."""

    def setup(self) -> None:
        from toolkit import plugins

        spec = self.spec_
        self.axis = clips.heading_axis(spec.clip, spec.heading_axis)
        self.ref = SpacetimeReference(spec.clip, self.axis, spec.loop, spec.cycle_turn, spec.straighten)
        self.ee_links = end_effector_links(self.sim)  # resolved once: the bounds read them every step
        # allowed contacts by the skeleton's link order: the simulator's link indices on the humanoid
        # (tests/plugins/jt_tasks/test_link_names.py)
        per_clip = clips.allowed_links(self.skeleton, spec.clip)
        self.train_allowed = per_clip if spec.train_allowed is None else tuple(spec.train_allowed)
        self.eval_allowed = per_clip if spec.eval_allowed is None else tuple(spec.eval_allowed)
        self.substeps = int(self.sim.n_substeps)
        self.control_hz = self.sim_hz / self.substeps
        self.names = bd.channel_names(self.skeleton)
        self.widths = np.asarray(spec.widths, dtype=float) if len(spec.widths) else bd.widths(self.skeleton)
        self.width_table = np.asarray(spec.width_table, dtype=float).reshape(-1, len(self.names))
        self.style_terms = [(str(t["name"]), plugins.load("reward", str(t["name"]))(
            {k: v for k, v in t.items() if k != "name"})) for t in spec.style]
        self.evaluating = False
        self._start(0.0 if spec.init_phase is None else float(spec.init_phase))

    # ------------------------------------------------------------------ episode bookkeeping
    def widths_at(self, phase: float) -> np.ndarray:
        """The bound widths ``(n_channels,)`` at clip ``phase``: the phase table's there, else the
        constant ones."""
        return bd.widths_at(self.width_table, phase) if len(self.width_table) else self.widths

    def _rule(self, allowed: tuple) -> tuple:
        forbidden = [i for i in range(-1, self.n_links) if i not in set(int(a) for a in allowed)]
        if not forbidden:
            return ()
        return (ContactRule(self.sim.ground, "fail", "forbidden ground contact", links=tuple(forbidden)),)

    def _start(self, phase: float, evaluate: bool = False, state: Optional[np.ndarray] = None) -> None:
        spec = self.spec_
        self.evaluating = bool(evaluate)
        self.eval_bodies: list[tuple[np.ndarray, np.ndarray]] = []  # (link CoMs, joint origins) per evaluation step
        self.phase0 = float(phase if state is None else min(max(float(state[0]), 0.0), 1.0))
        self.t0 = self.phase0 * self.ref.period
        ref = self.ref.sample(self.t0)
        if state is None:
            q, qd = ref.q, ref.qd
        else:  # an evolved state (002 §4.3.2), root x, z at the reference's (authors' code)
            n_q = len(ref.q)
            q, qd = np.array(state[1:1 + n_q], dtype=float), np.array(state[1 + n_q:], dtype=float)
            q[0], q[2] = ref.q[0], ref.q[2]
        self.sim.reset(q, qd)
        low = self.lowest_point()
        self.start_lift = 0.0
        if low < 0.0:  # a start that penetrates the ground is lifted (authors' code); others stay
            self.start_lift = float(spec.ground_clearance) - low
            q = np.array(q, dtype=float)
            q[1] += self.start_lift
            self.sim.reset(q, qd)
        if hasattr(self.action_space_, "reset"):
            self.action_space_.reset(ref.phase)
        if evaluate:
            limit, rules = float(spec.eval_time_limit), self._rule(self.eval_allowed)
        else:
            limit = float(spec.time_limit)
            if not self.ref.loop:
                limit = min(limit, self.ref.period + float(spec.hold_s) - self.t0)
            rules = self._rule(self.train_allowed) if spec.termination == "contact" else ()
        self.limit = max(limit, 1.0 / self.control_hz)
        self.watch = Watch(rules=rules, time_limit=self.limit, time_limit_outcome="truncate")
        self._inv = None
        self.steps = 0
        self.reward_sum = 0.0
        self.last_d = np.zeros(len(self.names))
        self._links_now = self._links_prev = self.sim.link_states()[0] if self.style_terms else None
        self._vel_prev = self._qd_prev = None
        if evaluate:
            self._record_body()

    def lowest_point(self) -> float:
        """M, the lowest point of the character now (its links' bounding boxes)."""
        return float(min(self.sim.aabb(i)[0][1] for i in range(-1, self.n_links)))

    def _record_body(self) -> None:
        """Keep the evaluation's bodies (link CoMs, joint origins) now, for its style measures."""
        self.eval_bodies.append((self.sim.link_states()[0], self.sim.link_poses(range(self.n_links))[0]))

    @property
    def t(self) -> float:
        """Time since the episode start (s)."""
        return float(self.sim.time)

    @property
    def clip_time(self) -> float:
        """Reference clip time of the current state (s)."""
        return self.t0 + self.t

    def heading_inverse(self) -> np.ndarray:
        """The inverse ``(4,)`` of the root's heading rotation now (``heading_quat``), computed once
        per state: the bounds' end effectors and the observation both use it."""
        if self._inv is None:
            q, _ = self.sim.state()
            self._inv = rot.quat_conjugate(heading_quat(q[3:7], self.axis))
        return self._inv

    def body_state(self) -> bd.BodyState:
        """What the bounds compare of the simulated character now."""
        q, _ = self.sim.state()
        ee = self.sim.link_poses(self.ee_links)[0]
        return bd.BodyState(q, np.asarray(self.sim.com(), dtype=float),
                            heading_frame(q, ee, self.axis, self.heading_inverse()))

    def difference(self) -> np.ndarray:
        """The 22-channel difference vector to the reference now (``bounds.difference`` of
        ``body_state()`` and the reference's, in one compiled pass)."""
        from jt_tasks.spacetime import kernels

        ref = self.ref.sample(self.clip_time)
        q, _ = self.sim.state()
        ee = self.sim.link_poses(self.ee_links)[0]
        out = np.zeros(len(self.names))  # the wrists (fixed joints) stay 0
        kernels.difference(np.asarray(q, dtype=float), np.asarray(self.sim.com(), dtype=float), ee, ref.q, ref.com,
                           ref.ee, self.axis == "z", *bd._angle_columns(self.skeleton), out)
        return out

    # ------------------------------------------------------------------ gymnasium hooks
    def start(self, options: Optional[dict]) -> dict:
        options = options or {}
        evaluate, state, segment = bool(options.get("evaluate", False)), None, -1
        pay = self.start_sampling
        if options.get("phase") is not None:
            phase = float(options["phase"])
        elif self.spec_.init_phase is not None:
            phase = float(self.spec_.init_phase)
        elif pay is None or evaluate:
            phase = float(self.np_random.uniform(0.0, 1.0))
        else:  # 002 §4.3: eq 11 segment, then a reference phase in it or an eq 12 buffer state
            probs = np.asarray(pay["probs"], dtype=float)
            segment = int(self.np_random.choice(len(probs), p=probs / probs.sum()))
            phase = (segment + float(self.np_random.uniform(0.0, 1.0))) / len(probs)
            count = int(np.asarray(pay["count"])[segment]) if pay.get("count") is not None else 0
            if count > 0 and float(self.np_random.uniform(0.0, 1.0)) < float(pay.get("share", 1.0)):
                state = np.asarray(pay["states"])[segment, int(self.np_random.integers(count))]
        self._start(phase, evaluate, state)
        return {"start_phase": self.phase0, "start_segment": float(segment), "from_buffer": float(state is not None)}

    def visit_state(self) -> Optional[np.ndarray]:
        """``[phase, q (root x, z = 0), qd]`` ``(1 + n_q + n_qd,)`` of the state now, for the
        evolution's buffers (002 §4.3.2); None when the spec's evolution is off or evaluating."""
        if not self.spec_.sampling.get("evolution") or self.evaluating:
            return None
        q, qd = self.sim.state()
        q = np.array(q, dtype=float)
        q[0] = q[2] = 0.0
        phase = self.ref.phase(self.clip_time)
        return np.concatenate([[phase], q, np.asarray(qd, dtype=float)])

    def pd_targets(self, action: np.ndarray) -> np.ndarray:
        if hasattr(self.action_space_, "set_phase"):  # the FFC's phase: this control step's (+ the lead)
            lead = float(self.spec_.ffc_lead) / self.control_hz
            self.action_space_.set_phase(self.ref.phase(self.clip_time + lead))
        return super().pd_targets(action)

    def pd_velocity_targets(self) -> Optional[np.ndarray]:
        """With ``ffc_velocity``: the reference's joint velocities ``(n_dof,)`` at the FFC's time
        (root entries 0), the PD target velocity; else None (zero target velocity, 002 / authors)."""
        if not self.spec_.ffc_velocity:
            return None
        lead = float(self.spec_.ffc_lead) / self.control_hz
        qd = np.array(self.ref.sample(self.clip_time + lead).qd, dtype=float)
        qd[:6] = 0.0
        return qd

    def observe(self) -> np.ndarray:
        from jt_tasks.spacetime import kernels

        q, qd = self.sim.state()
        pos, orn = self.sim.link_states()
        if self.spec_.velocities == "links":
            lin, ang = self.sim.link_velocities()
            obs = np.empty(2 + 13 * len(pos), dtype=np.float32)
        else:
            lin = ang = _NO_LINKS
            obs = np.empty(2 + 7 * len(pos) + len(qd), dtype=np.float32)
        half = -0.5 * self.ref.cycle_yaw(self.clip_time)
        kernels.observe(np.asarray(q, dtype=float), np.asarray(qd, dtype=float), pos, orn, lin, ang,
                        self.ref.phase(self.clip_time), self.axis == "z", self.spec_.root_orientation == "world",
                        math.sin(half), math.cos(half), obs)
        return obs

    def style_reward(self, q: np.ndarray, qd: np.ndarray) -> float:
        """Product of the style terms (1 without any). Their record: ``link_pos`` / ``link_vel`` /
        ``link_acc`` ``(n_links + 1, 3)`` (centres of mass; velocities and accelerations by
        differences over the control step, accelerations 0 at an episode's first step), ``masses``,
        ``joint_pos`` ``(n_links, 3)`` (joint origins), ``q``, ``qd``, ``joint_acc`` ``(n_dof,)``
        (internal dofs, by differences of ``qd``), ``clip`` (the reference clip's name or path)."""
        if not self.style_terms:
            return 1.0
        pos = self._links_now
        vel = (pos - self._links_prev) * self.control_hz
        qd = np.asarray(qd, dtype=float)
        acc = np.zeros_like(vel) if self._vel_prev is None else (vel - self._vel_prev) * self.control_hz
        jacc = np.zeros(len(qd) - 6) if self._qd_prev is None else (qd[6:] - self._qd_prev[6:]) * self.control_hz
        self._vel_prev, self._qd_prev = vel, qd.copy()
        joints = self.sim.link_poses(range(self.n_links))[0]
        record = {"q": q, "qd": qd, "link_pos": pos, "link_vel": vel, "link_acc": acc, "joint_acc": jacc,
                  "joint_pos": joints, "masses": self.masses, "clip": self.spec_.clip}
        out = 1.0
        for _, term in self.style_terms:
            out *= float(term(record))
        return out

    def finish_step(self, rec: dict[str, Any]) -> tuple[float, bool, bool, dict]:
        self._inv = None
        self.steps += 1
        if self.evaluating:  # the style measures of the evaluation (artifacts.style_measures)
            self._record_body()
        if self.style_terms:
            self._links_prev, self._links_now = self._links_now, self.sim.link_states()[0]
        outcome, reason = rec["outcome"], ""
        reward, terminated, truncated = 0.0, False, False
        if rec["failed"]:
            terminated, reason = True, self.failure(rec)
        elif self.evaluating:
            reward = 1.0
            terminated, truncated = outcome == "fail", outcome == "truncate"
            reason = rec["reason"] if outcome else ""
        elif self.spec_.termination == "bounds":
            self.last_d = d = self.difference()
            out = bd.violations(d, self.widths_at(self.ref.phase(self.clip_time)), self.names)
            if out:
                terminated, reason = True, "out of bounds: " + ",".join(out)
            else:
                reward = self.task_reward()
                truncated = outcome == "truncate"
                reason = rec["reason"] if truncated else ""
        else:
            if outcome == "fail":
                terminated, reason = True, rec["reason"]
            else:
                reward = self.imitation() if self.spec_.mix is None else self.task_reward()
                truncated = outcome == "truncate"
                reason = rec["reason"] if truncated else ""
        self.reward_sum += reward
        if not (terminated or truncated):
            return float(reward), False, False, {}
        info = {"reason": reason, "survival_s": self.t, "episode_time": self.t, "steps": float(self.steps),
                "start_phase": self.phase0, "fell": float(terminated), "time_out": float(truncated)}
        if reason.startswith("out of bounds"):
            for name in reason[len("out of bounds: "):].split(","):
                info[f"out_{name}"] = 1.0
        return float(reward), terminated, truncated, info

    def task_reward(self) -> float:
        """The reward of a control step inside the bounds (or, in the contact arm, without a
        forbidden contact): the style product (002 §5: survival 1 × style), or with ``mix = w_s``
        the eq 13 blend ``(1 − w_s) r_imitation + w_s r_style`` (002 §5.3.1, Table 2)."""
        q, qd = self.sim.state()
        style = self.style_reward(q, qd)
        if self.spec_.mix is None:
            return style
        w = float(self.spec_.mix)
        return (1.0 - w) * self.imitation() + w * style

    def imitation(self) -> float:
        """DeepMimic's imitation reward (Peng et al. 2018 §6) of the current state vs the reference."""
        from jt_tasks.runup.reward import imitation_terms

        q, qd = self.sim.state()
        ref = self.ref.sample(self.clip_time)
        me = self.body_state()
        return float(imitation_terms(self.skeleton, q, qd, me.ee, me.com, ref.q, ref.qd, ref.ee, ref.com)["imitation"])

    def close(self) -> None:
        self.ref = None
        super().close()
