"""``task=spd_tracking``: SPD mocap tracking over time steps (thesis ``001`` §2.4.1-2.4.2).

One evaluation tracks a reference motion (``task.motion``) with the character from
``character=...`` and the SPD backend from ``spd=...``: SPD on every internal joint and a
hand-of-God SPD servo on the root (``root_kp``/``root_kd``), one fixed set of gains for all
(§2.4.1), gravity and ground on (``sim.*``). For each dt in ``rates_hz`` it simulates the motion at
sim rate = control rate = 1/dt (one SPD solve per step, targets = the reference one step ahead)
and records the end-effector-to-root tracking error per step (Figs 2.4/2.5). It times the
simulator at dt = 1/30 (humanoid, snakes) or 1/240 (laikago) for the FPS (Table 2.2) and the SPD
share of the step time (Table 2.3).

Files (in the evaluation's workdir): ``spd_tracking.h5``, ``tracking_error.png`` and, with
``render: true``, ``filmstrip.png`` + ``tracking.gif``.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any, ClassVar, Optional, Sequence

from jt_tasks.spd_tracking.motions import WaveParams
from toolkit.config import plain
from toolkit.interfaces import EvalContext, Evaluation, Task
from toolkit.errors import JtError

FPS_RATE = {"laikago": 240.0}  #: 001 §2.4.2: dt = 1/240 for the dog, 1/30 otherwise
DEFAULT_FPS_RATE = 30.0


@dataclasses.dataclass
class SPDTrackingConfig:
    """Parameters of ``task=spd_tracking`` (the ``task`` group)."""

    name: str = "spd_tracking"
    """Registry name."""
    motion: str = "auto"
    """humanoid: walk, run, cartwheel, backflip (any humanoid3d_* clip); laikago: walk; snakes:
    slither (generated); or a DeepMimic .txt path. auto: run / walk / slither."""
    rates_hz: list[float] = dataclasses.field(
        default_factory=lambda: [30.0, 60.0, 120.0, 240.0, 600.0])
    """1/dt of each tracking run, Hz (001 §2.4.1: dt = 1/30 ... 1/600)."""
    duration: float = 0.0
    """Simulated seconds per dt; 0: two cycles of the motion."""
    kp: Optional[float] = 75000.0
    """Stiffness of every internal joint (001 §2.4.1); null keeps the character's own gains."""
    kd: Optional[float] = 4000.0
    """Damping of every internal joint (001 §2.4.1); null keeps the character's own."""
    root_kp: float = 20000.0
    """Hand-of-God root stiffness, position and orientation (001 §2.4.1)."""
    root_kd: float = 2000.0
    """Hand-of-God root damping (001 §2.4.1)."""
    torque_limits: bool = False
    """Clip torques to the character's limits (the thesis' tracking names none: off)."""
    target_velocity: bool = True
    """SPD target velocities = the reference's (else zero, eq 2.4 as printed: lags ~kd/kp qd)."""
    diverge_error: float = 1.0
    """A tracking error above this (m) counts as divergence, like a NaN or exploding state."""
    fps_rate_hz: float = 0.0
    """1/dt of the timing run; 0: 240 for laikago, 30 otherwise (001 §2.4.2)."""
    fps_duration: float = 10.0
    """Simulated seconds of the (separate) timing run; 0: time the error run at fps_rate_hz."""
    fps_repeats: int = 3
    """Timing runs; the fastest counts (the least disturbed by other load on the machine)."""
    render: bool = False
    """Render the run at render_rate_hz: filmstrip.png and tracking.gif (TinyRenderer)."""
    render_rate_hz: float = 0.0
    """1/dt of the rendered run; 0: the largest of rates_hz."""
    render_fps: float = 30.0
    """Frames per simulated second in the GIF."""
    render_width: int = 320
    """Frame width, px (at least 320: a picture shows the character at every budget)."""
    render_height: int = 240
    """Frame height, px."""
    filmstrip_frames: int = 8
    """Frames in filmstrip.png."""
    wave: WaveParams = dataclasses.field(default_factory=WaveParams)
    """The snakes' travelling wave (ours; see jt_tasks.spd_tracking.motions)."""

    def check(self) -> None:
        """One ``JtError`` line at composition for a rate list, a duration or a timing set-up out of range."""
        from toolkit.schema import require

        require(bool(self.rates_hz) and all(float(r) > 0 for r in self.rates_hz), "task.rates_hz",
                list(self.rates_hz), "one or more rates > 0 Hz")
        require(float(self.duration) >= 0, "task.duration", self.duration, "must be >= 0 s (0: two cycles)")
        for key in ("fps_rate_hz", "fps_duration", "render_rate_hz"):
            require(float(getattr(self, key)) >= 0, f"task.{key}", getattr(self, key), "must be >= 0 (0: the default)")
        require(int(self.fps_repeats) >= 1, "task.fps_repeats", self.fps_repeats, "must be >= 1")


class SPDTrackingTask(Task):
    """Mocap tracking with SPD and a hand-of-God root over time steps: error, FPS, SPD share."""

    ignores_groups: ClassVar[tuple[str, ...]] = ("action", "reward", "curriculum")

    Config: ClassVar[type] = SPDTrackingConfig
    timing_metrics: ClassVar[tuple[str, ...]] = ("fps", "spd_share_pct", "step_us", "spd_us")
    curve_prefix: ClassVar[str] = "tracking/"
    """Its curves are tracking error over simulation steps, not training curves."""
    key_metrics: ClassVar[tuple[str, ...]] = ("fps", "spd_share_pct", "err_mean_dt30",
                                              "err_mean_dt600", "n_diverged")

    @classmethod
    def check_run(cls, cfg: Any) -> None:
        """``task.motion`` names a clip of the character (a wrong name is one line before the run
        opens, listing the character's clips)."""
        import os

        from toolkit.config import group_of
        from toolkit.errors import JtError

        from jt_tasks.spd_tracking.motions import default_motion, motion_path

        from toolkit import plugins

        task = group_of(cfg, "task")
        spd = str(group_of(group_of(cfg, "spd"), "name") or "")
        if float(group_of(task, "root_kp") or 0.0) != 0.0 and spd and \
                getattr(plugins.load("spd", spd), "steps_itself", False):
            able = [n for n in plugins.names("spd") if not getattr(plugins.load("spd", n), "steps_itself", False)]
            raise JtError(f"spd={spd} cannot drive the tracking's root servo (task.root_kp: it computes its torques "
                          f"inside the step and leaves the root unactuated); use spd={'/'.join(able)} or task.root_kp=0")
        character = group_of(cfg, "character")
        name = str(group_of(character, "name") or "humanoid") if character is not None else "humanoid"
        motion = str(group_of(task, "motion") or "auto")
        motion = default_motion(name) if motion in ("auto", "") else motion
        if name.startswith("snake") and motion != "slither":
            raise JtError(f"task.motion={motion}: the snakes track the generated 'slither' (task.motion=auto)")
        if motion == "slither" and not name.startswith("snake"):
            raise JtError(f"task.motion=slither is for the snakes, not character={name}")
        if not motion:
            raise JtError(f"character={name}: no motion to track; tracking supports humanoid (mocap clips), "
                          "laikago (walk) and the snakes (slither)")
        if motion == "slither":
            return
        try:
            path = motion_path(name, motion)
        except JtError as e:
            raise JtError(f"task.motion={motion}: {e}") from None
        if not os.path.isfile(path):
            raise JtError(f"task.motion={motion}: no such file")
        from toolkit.motion.clips import ClipError, load_clip

        try:  # read now, before a run opens: a file that is no clip (bad JSON, one frame) is one line
            load_clip(path)
        except ClipError as e:
            raise JtError(f"task.motion={motion}: {e}") from None

    def __init__(self, cfg: Any) -> None:
        from toolkit.config import config_of

        super().__init__(cfg)
        whole = plain(cfg)
        self.params: SPDTrackingConfig = config_of(SPDTrackingConfig, whole.get("task"), "task")
        self.whole = whole

    # ------------------------------------------------------------------ config of the runs
    def run_config(self) -> dict:
        """``sim`` / ``character`` / ``spd`` for the tracking runs (gains and servo applied)."""
        p, w = self.params, self.whole
        sim = dict(w.get("sim") or {"name": "bullet"})
        sim.update(torque_limits=p.torque_limits, contacts=False,
                   root_servo={"kp": float(p.root_kp), "kd": float(p.root_kd)})
        character = w.get("character") or {"name": "humanoid"}
        character = {"name": character} if isinstance(character, str) else dict(character)
        if p.kp is not None:
            character["kp"] = float(p.kp)
        if p.kd is not None:
            character["kd"] = float(p.kd)
        spd = dict(w.get("spd") or {"name": "maba"})
        return {"sim": sim, "character": character, "spd": spd}

    def reference(self, run_cfg: dict) -> tuple[Any, dict]:
        """The reference motion and model facts (``dof``, ``depth``, ``n_q``, end-effector), read
        from a simulator instance of the run's config (the registry's ``sim``)."""
        from jt_tasks.spd_tracking.motions import make_reference
        from jt_tasks.spd_tracking.tracking import end_effector, simulator_class

        sim = simulator_class(run_cfg)(run_cfg)
        try:
            ch = sim.character
            ref = make_reference(ch, self.params.motion, self.params.wave)
            model = sim.model
            facts = {"character": ch.name, "dof": model.n_v, "depth": model.depth,
                     "n_q": model.n_q, "end_effector": end_effector(sim)[0]}
        finally:
            sim.close()
        return ref, facts

    # ------------------------------------------------------------------ evaluation
    def evaluate(self, point: dict[str, float], ctx: EvalContext) -> Evaluation:
        from omegaconf import OmegaConf

        from jt_tasks.spd_tracking import artifacts
        from jt_tasks.spd_tracking.tracking import track

        p = self.params
        run_cfg = self.run_config()
        ref, facts = self.reference(run_cfg)
        duration = p.duration if p.duration > 0 else 2.0 * ref.duration
        rates = [float(r) for r in p.rates_hz]
        if not rates or any(not r > 0 for r in rates):
            raise JtError(f"task.rates_hz must be positive rates, got {p.rates_hz}")
        fps_rate = p.fps_rate_hz or FPS_RATE.get(facts["character"], DEFAULT_FPS_RATE)
        render_rate = (p.render_rate_hz or max(rates)) if p.render else None
        plan = sorted(set(rates) | ({float(render_rate)} if render_rate else set()))
        separate = p.fps_duration > 0
        if not separate:
            plan = sorted(set(plan) | {float(fps_rate)})
        runs, timing, frames = [], None, []
        n_runs = len(plan) + int(separate)
        for i, rate in enumerate(plan):
            ctx.report(i / n_runs, f"dt = 1/{rate:g}")
            every = 1.0 / p.render_fps if render_rate and rate == float(render_rate) else None
            res = track(run_cfg, ref, rate, duration, p.target_velocity, p.diverge_error,
                        render_every=every, render_size=(p.render_width, p.render_height))
            if not separate and rate == float(fps_rate):
                timing = res
            if every:
                frames = res.frames
            res.frames = []
            if rate in rates:
                runs.append(res)
        if separate:
            ctx.report(len(plan) / n_runs, f"timing at dt = 1/{fps_rate:g}")
            for _ in range(max(1, p.fps_repeats)):
                res = track(run_cfg, ref, fps_rate, p.fps_duration, p.target_velocity,
                            p.diverge_error)
                if timing is None or res.fps > timing.fps:
                    timing = res
        ctx.report(1.0, "done")
        assert timing is not None
        info = {**facts, "backend": str(run_cfg["spd"].get("name")), "motion": ref.name,
                "fps": timing.fps, "fps_rate_hz": fps_rate, "fps_steps": timing.substeps,
                "spd_share_pct": 100.0 * timing.spd_share}
        work = Path(ctx.workdir)
        work.mkdir(parents=True, exist_ok=True)
        artifacts.write_h5(work / "spd_tracking.h5", runs, info,
                           OmegaConf.to_yaml(OmegaConf.create(self.whole)))
        title = (f"{facts['character']} {ref.name}, spd={info['backend']}: "
                 f"|(ee - root)_sim - (ee - root)_ref| at {facts['end_effector']}")
        artifacts.plot_errors(work / "tracking_error.png", runs, title)
        artifacts.save_frames(work, frames, p.filmstrip_frames, p.render_fps)
        metrics = artifacts.metrics_of(runs, timing.fps, timing.spd_share)
        metrics.update(fps_steps=float(timing.substeps), dof=float(facts["dof"]),
                       depth=float(facts["depth"]))
        history = {}  # error curves for MLflow, at most ~200 points each (the HDF5 has all)
        for r in runs:
            stride = max(1, len(r.error) // 200)
            history[f"err_{artifacts.rate_key(r.rate_hz)}"] = [
                (k, float(r.error[k])) for k in range(0, len(r.error), stride)
                if math.isfinite(r.error[k])]
        all_diverged = all(r.diverged for r in runs)
        return Evaluation(metrics=metrics, failed=all_diverged,
                          reason="diverged at every dt" if all_diverged else "", history=history)

    def summarize(self, evaluations: Sequence[Evaluation], workdir: Path) -> dict[str, float]:
        """The (single) evaluation's metrics, averaged if there are several."""
        import numpy as np

        if not evaluations:
            return {}
        keys = set().union(*(e.metrics for e in evaluations))
        return {k: float(np.nanmean([e.metrics.get(k, math.nan) for e in evaluations]))
                if any(math.isfinite(e.metrics.get(k, math.nan)) for e in evaluations) else math.nan
                for k in sorted(keys)}
