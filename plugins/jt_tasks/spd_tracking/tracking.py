"""One tracking run: a reference motion simulated at one time step, the per-step error measured.

At rate ``r = 1/dt`` the simulator runs one SPD solve per step (``sim_hz = control_hz = r``);
step ``k`` targets the reference at ``t_{k+1}`` (SPD targets one step ahead, thesis ``001``
eq 2.4). The error after each step is (thesis §2.4.1)

    e_k = || (p_ee - p_root)_sim(t_k) - (p_ee - p_root)_ref(t_k) ||      (metres, world frame)

with ``p_root`` the base position and ``p_ee`` the end-effector (humanoid: right ankle joint;
laikago: right front toe; snake: the tail tip). The reference vectors come from a kinematic
copy of the character in a second simulator instance (reset to each reference pose, read by
``link_pose``). The simulator is the configured plugin, found through the registry. A NaN or
exploding state, or an error above ``diverge_error``, stops the run as diverged; the remaining
errors are NaN.
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Any, Optional

import numpy as np

from toolkit.interfaces.simulator import BASE

END_EFFECTORS = {  # character: (link name, offset in the link frame)     001 §2.4.1 (ours: snake)
    "humanoid": ("right_ankle", (0.0, 0.0, 0.0)),
    "laikago": ("toeFR", (0.0, 0.0, 0.0)),
    "atlas": ("r_foot", (0.0, 0.0, 0.0)),
}


def end_effector(sim: Any) -> tuple[str, tuple[float, float, float]]:
    """``(link name, offset in the link frame)`` of the tracked end-effector of a simulator's
    character (its ``character``: ``name``, ``joint_indices``), read before any step."""
    ch = sim.character
    name = ch.name
    if name.startswith("snake"):
        k = len(ch.joint_indices)
        return f"seg{k}", (0.5 * _segment_length(sim), 0.0, 0.0)  # tail tip
    return END_EFFECTORS[name]


@dataclasses.dataclass
class TrackResult:
    """What one tracking run measured (arrays over completed steps ``(n,)``)."""

    rate_hz: float
    time: np.ndarray
    error: np.ndarray
    ee_sim: np.ndarray
    ee_ref: np.ndarray
    diverged: bool
    reason: str
    n_steps: int
    spd_s: float
    substep_s: float
    substeps: int
    wall_s: float
    spd_median_s: float = math.nan
    substep_median_s: float = math.nan
    frames: list = dataclasses.field(default_factory=list)

    @property
    def fps(self) -> float:
        """Simulated steps per second: 1 / the median step time (read state, SPD, clip, apply,
        ``stepSimulation``); the median shrugs off bursts of other load on the machine."""
        return 1.0 / self.substep_median_s if self.substep_median_s > 0 else math.nan

    @property
    def spd_share(self) -> float:
        """Median SPD solve time over median step time (NaN when the solve runs in PyBullet)."""
        if not (self.substep_median_s > 0 and self.spd_median_s > 0):
            return math.nan
        return self.spd_median_s / self.substep_median_s


def _ee_vector(sim: Any, link: int, offset: np.ndarray) -> np.ndarray:
    """``p_ee - p_root`` ``(3,)`` now: the link frame's origin (plus ``offset`` ``(3,)`` in that
    frame) minus the base position, world frame."""
    p, q = sim.link_pose(link)
    if offset.any():
        p = p + _rotate(q, offset)
    base, _ = sim.link_pose(BASE)
    return p - base


def _rotate(q: Any, v: np.ndarray) -> np.ndarray:
    from toolkit.motion.rotations import quat_rotate

    return quat_rotate(np.array(q), v)


def _segment_length(sim: Any) -> float:
    """Length of a snake segment: the distance between its last two joint origins, as loaded."""
    a, b = sim.character.joint_indices[-2:]
    pa, _ = sim.link_pose(a)
    p_b, _ = sim.link_pose(b)
    return float(np.linalg.norm(np.subtract(p_b, pa)))


def simulator_class(run_cfg: Any) -> Any:
    """The configured simulator plugin class, through the registry."""
    from toolkit import plugins

    return plugins.load("sim", str((run_cfg.get("sim") or {}).get("name", "bullet")))


def reference_vectors(run_cfg: Any, ref: Any, times: np.ndarray) -> np.ndarray:
    """``(p_ee - p_root)`` of the reference at ``times`` ``(n,)`` → ``(n, 3)``: a simulator of its
    own reset to each pose (zero velocity, no step) and read by forward kinematics."""
    sim = simulator_class(run_cfg)(run_cfg)
    try:
        link_name, off = end_effector(sim)
        link = sim.link_index(link_name)
        zero = np.zeros(sim.model.n_v)
        out = np.empty((len(times), 3))
        for i, q in enumerate(ref.poses(np.asarray(times, dtype=float))):
            sim.reset(q, zero)
            out[i] = _ee_vector(sim, link, np.asarray(off, float))
        return out
    finally:
        sim.close()


def track(run_cfg: dict, ref: Any, rate_hz: float, duration: float, target_velocity: bool = True,
          diverge_error: float = 1.0, render_every: Optional[float] = None,
          render_size: tuple[int, int] = (240, 180)) -> TrackResult:
    """Simulate ``ref`` for ``duration`` seconds at ``rate_hz`` and measure the tracking error.

    Args:
        run_cfg: the run config as a plain dict (``sim``, ``character``, ``spd``); its
            ``sim.sim_hz`` and ``sim.control_hz`` are replaced by ``rate_hz``.
        ref: a ``motions.Reference``.
        rate_hz: 1 / dt.
        duration: simulated seconds.
        target_velocity: SPD target velocities from the reference (else zero).
        diverge_error: an error above this (m) counts as divergence.
        render_every: capture a frame every this many simulated seconds (None: no frames).
        render_size: ``(width, height)`` of captured frames.
    """
    cfg = {**run_cfg, "sim": {**run_cfg.get("sim", {}), "sim_hz": float(rate_hz),
                              "control_hz": float(rate_hz)}}
    n = max(1, int(round(duration * rate_hz)))
    times = np.arange(1, n + 1) / float(rate_hz)
    ee_ref = reference_vectors(cfg, ref, times)
    targets = ref.poses(times)
    vels = ref.velocities(times) if target_velocity else [None] * n
    sim = simulator_class(cfg)(cfg)
    try:
        link_name, off = end_effector(sim)
        link = sim.link_index(link_name)
        off = np.asarray(off, float)
        q0, v0 = ref.pose(0.0), ref.velocity(0.0)
        sim.reset(q0, v0)
        if not sim.steps_itself:  # JIT / caches warm before timing; no effect on the world
            sim.backend.torques(q0, v0, targets[0], sim.kp, sim.kd, sim.dt, vels[0])
        sim.reset_timers()
        sim.step_log = log = []
        err = np.full(n, np.nan)
        ee_sim = np.full((n, 3), np.nan)
        frames: list = []
        next_frame = 0.0
        diverged, reason, done = False, "", 0
        if render_every:
            frames.append(sim.render(*render_size))
            next_frame = render_every
        t0 = time.perf_counter()
        for k in range(n):
            rec = sim.step(targets[k], vels[k])
            if rec["failed"]:
                diverged, reason = True, rec["reason"]
                break
            v = _ee_vector(sim, link, off)
            ee_sim[k] = v
            e = float(np.linalg.norm(v - ee_ref[k]))
            err[k] = e
            done = k + 1
            if not e <= diverge_error:
                diverged = True
                reason = f"tracking error {e:.3g} m > diverge_error {diverge_error:g}"
                err[k] = np.nan
                break
            if render_every and times[k] + 1e-9 >= next_frame:
                frames.append(sim.render(*render_size))
                next_frame += render_every
        wall = time.perf_counter() - t0
        tm = sim.timers
        med = np.median(np.array(log), axis=0) if log else (math.nan, math.nan)
        return TrackResult(rate_hz=float(rate_hz), time=times, error=err, ee_sim=ee_sim,
                           ee_ref=ee_ref, diverged=diverged, reason=reason, n_steps=done,
                           spd_s=tm["spd_s"], substep_s=tm["substep_s"], substeps=tm["substeps"],
                           wall_s=wall, spd_median_s=float(med[0]),
                           substep_median_s=float(med[1]), frames=frames)
    finally:
        sim.close()
