"""The run-up environment (``gymnasium.Env``): imitate the reference run, reach the take-off features.

DeepMimic (Peng et al. 2018) as ``000`` §6.1.1 uses it for the run-up controllers:

* reference state initialisation: each episode starts in the reference state at a random clip
  time ``t0`` (uniform over one cycle, drawn from the env's ``np_random``, rounded to the
  simulation grid ``1 / sim_hz``; ``reset(options={"time": t0})`` fixes it);
* the episode ends at the take-off instant: the ``n_strides``-th middle of a support phase of the
  take-off foot after ``t0`` (at least one control step later; same definition as
  ``jt_tasks.takeoff.state.support_phase_time``), so it lasts between ``n_strides - 1`` and ``n_strides`` cycles;
  the last control step runs only the substeps left to that instant;
* early termination: any body part other than the feet touching the ground, or a failed
  simulation (NaN / exploding), ends the episode without the task reward;
* control at ``sim.control_hz`` (30 Hz, Peng et al. 2018), ``round(sim_hz / control_hz)`` substeps at the simulator's
  rate (600 Hz), the action space plugin (``raw``: the action is the PD targets) giving the
  internal joints' PD targets.

Reward of a control step (``reward.py``): ``w_I r_I`` and, at the take-off instant only,
``w_G · goal_steps · r_G`` added (``goal_steps`` = the episode's number of control steps unless
set: the terminal r_G then weighs as if it had been earned on every step, so that the split of the
best return between imitation and goal is ``w_I : w_G``). The paper gives no weights; ours.

Observation ``(obs_dim,)`` float32, DeepMimic-like, in the facing frame of the root: root height,
root orientation (6D), root linear and angular velocity, joint positions (quaternions / angles)
and velocities, link centres of mass relative to the root, the clip phase (sin, cos) and the
strides left to the take-off.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Optional

import numpy as np

from jt_tasks.takeoff.state import FOOT_LINKS, heading_quat
from jt_tasks.runup.reference import END_EFFECTORS, RunReference, facing_frame
from jt_tasks.runup import reward as rw
from toolkit.policy.env import CharacterEnv
from jt_tasks.runup.config import RunupConfig as _C
from toolkit.interfaces.simulator import ContactRule, Watch
from toolkit.motion import rotations as rot


@dataclasses.dataclass
class RunupSpec(_C):
    """What a run-up environment runs from, as plain picklable data: every setting of the
    task's ``RunupConfig`` (inherited, so each is declared once, there, with its default and source),
    plus the values the task resolves from them (below; ``toolkit.policy.spec.spec_of``)."""

    target: dict = dataclasses.field(default_factory=dict)  # resolved: desired take-off features by name
    sim: dict = dataclasses.field(default_factory=dict)  # {"sim": ..., "spd": ..., "character": ...}
    action: dict = dataclasses.field(default_factory=lambda: {"name": "raw"})


class RunupEnv(CharacterEnv):
    """DeepMimic run-up (000 §6.1.1): imitate the run, end at take-off with the target features."""

    def setup(self) -> None:
        spec = self.spec_
        self.targets = rw.goal_targets(spec.kind, spec.target, spec.omega_y)
        self.substeps = max(1, int(round(self.sim_hz / self.control_hz)))
        self.feet = {self.sim.link_index(FOOT_LINKS["right"]), self.sim.link_index(FOOT_LINKS["left"])}
        # rows of the end effectors in links_and_com (base first) of the simulator and of the
        # reference's kinematic body alike: the humanoid skeleton's link order is the simulator's
        # link indices (tests/plugins/jt_tasks/test_link_names.py)
        self.ee_rows = [self.sim.link_index(name) + 1 for name in END_EFFECTORS]
        self.ref = RunReference(spec.clip, spec.foot, spec.contact_tol, spec.foot_clearance, self.sim_hz)
        # DeepMimic's early termination: a body part other than the feet touches the ground
        self.watch = Watch(rules=(ContactRule(self.sim.ground, "fail", "fell", except_links=tuple(sorted(self.feet))),),
                           check_every=spec.check_every)
        self._start(self.ref.t_mid)

    # ------------------------------------------------------------------ episode bookkeeping
    def _start(self, t0: float) -> None:
        """Reference state initialisation at clip time ``t0`` (rounded to the simulation grid)."""
        self.j0 = int(round(float(t0) * self.sim_hz))
        self.t0 = self.j0 / self.sim_hz
        self.t_takeoff = self.ref.takeoff_time(self.t0, self.spec_.n_strides, 1.0 / self.control_hz)
        self.total_substeps = max(1, int(round((self.t_takeoff - self.t0) * self.sim_hz)))
        self.n_steps = math.ceil(self.total_substeps / self.substeps)
        self.substeps_done = 0
        ref = self.ref.at(self.j0)
        q, qd = ref.q.copy(), ref.qd.copy()
        lift = self.spec_.foot_clearance - self.ref.lowest_point(q)
        if lift > 0:  # the clip's feet dip into the ground at some frames: never start inside it
            q[1] += lift
        self.sim.reset(q, qd)
        self.action_space_.reset(None)
        self.terms_log: list[dict[str, float]] = []

    @property
    def t(self) -> float:
        """Time since the episode start (s)."""
        return self.substeps_done / self.sim_hz

    @property
    def clip_time(self) -> float:
        """Reference clip time of the current state (s)."""
        return (self.j0 + self.substeps_done) / self.sim_hz

    def observe(self) -> np.ndarray:
        q, qd = self.sim.state()
        links, _ = self.links_and_com()
        hq = heading_quat(q[3:7])
        inv = rot.quat_conjugate(hq)
        r_local = rot.quat_multiply(inv, q[3:7])
        rel = facing_frame(q, links[1:])
        ph = 2.0 * math.pi * self.ref.phase(self.clip_time)
        left = (self.total_substeps - self.substeps_done) / (self.sim_hz * self.ref.period)
        parts = [[q[1]], rot.quat_to_6d(r_local), rot.quat_rotate(inv, qd[:3]), rot.quat_rotate(inv, qd[3:6]),
                 q[7:], qd[6:], rel.reshape(-1), [math.sin(ph), math.cos(ph), left]]
        return self.flat(parts)

    def imitation(self) -> dict[str, float]:
        """The imitation terms (``reward.imitation_terms``) of the current state vs the reference."""
        q, qd = self.sim.state()
        ref = self.ref.at(self.j0 + self.substeps_done)
        links, com = self.links_and_com()
        ee = self.ee_rows  # base is row 0
        return rw.imitation_terms(self.skeleton, q, qd, facing_frame(q, links[ee]), com,
                                  ref.q, ref.qd, facing_frame(ref.q, ref.links[ee]), ref.com)

    # ------------------------------------------------------------------ gymnasium hooks
    def start(self, options: Optional[dict]) -> dict:
        if options and options.get("time") is not None:
            t0 = float(options["time"])
        else:
            t0 = float(self.np_random.uniform(0.0, self.ref.period))
        self._start(t0)
        return {"start_time": self.t0, "takeoff_time": self.t_takeoff, "n_steps": self.n_steps}

    def substeps_now(self) -> int:
        return min(self.substeps, self.total_substeps - self.substeps_done)

    def finish_step(self, rec: dict[str, Any]) -> tuple[float, bool, bool, dict]:
        self.substeps_done += int(rec["substeps"])
        reason = self.failure(rec) or (rec["reason"] if rec["outcome"] else "")
        if reason.startswith("simulator"):  # NaN / exploded state: nothing to compare
            terms = {k: 0.0 for k in ("pose", "vel", "ee", "com", "imitation")}
        else:
            terms = self.imitation()
        self.terms_log.append(terms)
        reward = self.spec_.w_imitation * terms["imitation"]
        took_off = not reason and self.substeps_done >= self.total_substeps
        if not reason and not took_off:
            return float(reward), False, False, {}
        info = self._final_info(took_off, reason)
        if took_off:
            k_goal = float(self.n_steps if self.spec_.goal_steps is None else self.spec_.goal_steps)
            reward += self.spec_.w_goal * k_goal * info["r_goal"]
        return float(reward), True, False, info

    def _final_info(self, took_off: bool, reason: str) -> dict[str, Any]:
        q, qd = self.sim.state()
        finite = bool(np.all(np.isfinite(q)) and np.all(np.isfinite(qd)))
        achieved = rw.measure(q, qd) if finite else {k: 0.0 for k in rw.MEASURED}
        r_goal = rw.goal_reward(self.spec_.kind, achieved, self.targets) if took_off else 0.0
        info: dict[str, Any] = {"r_goal": float(r_goal), "took_off": float(took_off), "fell": float(not took_off),
                                "reason": reason or "take-off", "episode_time": self.t,
                                "start_time": self.t0, "steps": float(len(self.terms_log))}
        for k in ("imitation", "pose", "vel", "ee", "com"):
            info[f"r_{k}_mean"] = float(np.mean([t[k] for t in self.terms_log]))
        info.update({f"takeoff_{k}": v for k, v in achieved.items()})
        info.update({f"target_{k}": v for k, v in self.targets.items()})
        return info

    def close(self) -> None:
        if getattr(self, "ref", None) is not None:
            self.ref.close()
            self.ref = None
        super().close()
