"""``task=getup``: a get-up policy that tracks style curves (Frezzato et al. 2022, ``003``; docs/getup.md).

One evaluation = one get-up policy: PPO (``agent=ppo_getup``, §5.6) on ``GetupEnv`` over the
training curves (the DeepMimic get-up clips' curves and their mirrors, plus authored ones) from
the clips' first poses, settled rag-doll states and standing poses (§5.2), then deterministic
get-ups measured. The searched point is ``time_scale``: every curve's duration T times it (§4.3:
"the duration of the motion can be adjusted simply by changing the duration T").

Success (§6.3 "remains standing after getting up"; the thresholds are ours): an episode that is
not terminated early, from a fallen start (clip or rag-doll), whose neck height stays at or above
``success_height`` × p_h(1) for the last ``success_window`` s of its ``T + 3 s``.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any, ClassVar, Optional

import numpy as np

from toolkit.config import group_of, plain
from toolkit.interfaces.searcher import Param, SearchProblem, Space
from toolkit.interfaces.task import EvalContext, Evaluation

from jt_tasks.policy.task import Hooks, PolicyConfig, PolicyTask, require_humanoid_and_prior

_FALLEN: dict[tuple, list] = {}  #: fallen_states memo per process: {(groups, params): states}
HISTORY = ("success", "got_up", "r_task_mean", "task_return_rate")  #: per-iteration episode means


@dataclasses.dataclass
class GetupConfig(PolicyConfig):
    """The ``task`` group of ``task=getup`` (``jt run task=getup --cfg`` prints every value)."""

    name: str = "getup"
    """Registry name."""
    curves: list[str] = dataclasses.field(
        default_factory=lambda: ["facedown", "facedown_mirror", "faceup", "faceup_mirror"])
    """Training curves: reference curves of the DeepMimic get-up clips (and mirrors) or names in authored (003 §5.5 uses 13 reference + 5 authored x 3 durations; ours: the 2 clips jt has)."""
    authored: dict = dataclasses.field(default_factory=dict)
    """Authored curves {name: {h: [9], theta_x: [9], theta_z: [9], duration: s}} (003 §4.3, §5.5)."""
    authored_durations: list[float] = dataclasses.field(default_factory=list)
    """S; each authored curve once per duration (003 §5.5: 2.5, 5.1, 7.6); empty: its own duration."""
    n_control: int = 9
    """Control points per curve (003 §4.1: "nine control points are sufficient")."""
    extraction: str = "sample"
    """Reference curves: sample (003 §4.1, the features at 9 instants) or lstsq (ours: a least-squares fit)."""
    clamped: bool = True
    """Clamped end knots, uniform inside (ours, jt's splines: the curve starts and ends at its end points); false: unclamped cardinal."""
    t_stand: float = 3.0
    """S of standing after T in every episode (003 §5.6: T_stand = 3 s)."""
    p_standing: float = 0.1
    """Share of episodes starting standing (003 §5.2 "necessary"; the share is ours)."""
    p_fallen: float = 0.3
    """Share of episodes starting from a rag-doll state (003 §5.2; the share is ours); the rest start at the curve's clip's first pose (003 §5.5)."""
    n_fallen: int = 8
    """Rag-doll states generated per evaluation (ours)."""
    fallen_styles: list[str] = dataclasses.field(default_factory=lambda: ["prone", "supine"])
    """Rag-doll drop postures (003 §5.2: prone or supine)."""
    fallen_seed: int = 0
    """Seed of the rag-doll generator (ours)."""
    drop_height: float = 0.6
    """M, lowest point at release (ours)."""
    drop_perturb: float = 0.3
    """Rad, random joint perturbation of the drop pose (ours)."""
    ragdoll_kd: float = 1.0
    """N m s/rad, joint damping of the passive rag-doll (ours; 003: "passive")."""
    settle_max: float = 3.0
    """S allowed to come to rest (ours; drops settle within 3 s, notes)."""
    rest_speed: float = 0.05
    """At rest when every generalised speed is below this (ours)."""
    curve_match_deg: float = 30.0
    """A rag-doll start takes a curve whose start torso angles are within this (003 §5.2: 30°)."""
    r_task_min: float = 0.1
    """Early termination when r_task stays below this (003 §5.3)."""
    sustain: float = 0.3
    """S an early-termination condition must last (003 §5.3: 300 ms)."""
    head_grace: float = 1.0
    """S after a start with the head on the floor (supine, rag-doll) during which head contacts do not count (ours; 003 §5.3 has none)."""
    friction: Optional[float] = 1.0
    """Ground and link friction set on the simulator (003 §3.2: mu = 1.0); null: the sim group's."""
    success_height: float = 0.8
    """Standing = neck height >= this x p_h(1) (ours; 003 §6.3 gives no threshold)."""
    success_window: float = 1.0
    """S standing at the end of the episode that make a success (ours)."""
    heightmap_n: int = 5
    """Height-map samples per side (003 §3.3.2: 5 x 5)."""
    heightmap_spacing: float = 0.25
    """M between height-map samples (003 §3.2: 25 cm over 1 m)."""
    natural_terms: list[str] = dataclasses.field(default_factory=lambda: ["naturalness"])
    """Reward terms that make r_natural (003 eq 2); the others multiply to r_task (eq 4)."""
    eval_curve: str = "facedown"
    """Curve of the deterministic rollout (from its clip's first pose)."""
    eval_episodes: int = 4
    """Deterministic evaluation get-ups (the rollout, then the other curves' clip starts and rag-doll states in turn) giving success_rate (ours)."""
    time_scale: float = 1.0
    """Default of the searched point: every curve's T times this (003 §4.3)."""

    def check(self) -> None:
        """One-line ``JtError`` for each mistake (unknown curve or style, control-point count ...)."""
        from toolkit.schema import finite, require

        from jt_tasks.getup.curves import build_curves
        from jt_tasks.getup.initial import STYLES

        require(self.n_control >= 4, "task.n_control", self.n_control, "a cubic B-spline needs >= 4 control points")
        require(self.extraction in ("sample", "lstsq"), "task.extraction", self.extraction, "sample or lstsq")
        require(bool(self.curves), "task.curves", self.curves, "needs at least one curve")
        for d in self.authored_durations:
            require(finite(d) and float(d) > 0, "task.authored_durations", list(self.authored_durations),
                    "durations must be > 0 s")
        try:
            build_curves(list(self.curves), dict(self.authored), list(self.authored_durations) or None,
                         self.n_control, self.extraction, self.clamped)
        except (KeyError, ValueError) as e:
            require(False, "task.curves", list(self.curves), str(e.args[0] if e.args else e))
        bad = [s for s in self.fallen_styles if s not in STYLES]
        require(not bad and bool(self.fallen_styles), "task.fallen_styles", list(self.fallen_styles),
                f"each one of {', '.join(STYLES)}")
        require(self.eval_curve in self.curves, "task.eval_curve", self.eval_curve,
                f"must be one of task.curves ({', '.join(self.curves)})")
        require(self.eval_episodes >= 1, "task.eval_episodes", self.eval_episodes, "must be >= 1")
        require(self.n_fallen >= 0, "task.n_fallen", self.n_fallen, "must be >= 0")
        for key in ("p_standing", "p_fallen"):
            v = getattr(self, key)
            require(finite(v) and 0.0 <= v <= 1.0, f"task.{key}", v, "must be in [0, 1]")
        require(self.p_standing + self.p_fallen <= 1.0, "task.p_standing+p_fallen",
                self.p_standing + self.p_fallen, "must be <= 1")
        for key in ("t_stand", "sustain", "settle_max", "time_scale", "heightmap_spacing", "success_height"):
            v = getattr(self, key)
            require(finite(v) and v > 0, f"task.{key}", v, "must be a finite number > 0")
        for key in ("head_grace", "success_window", "r_task_min", "drop_height", "drop_perturb", "ragdoll_kd",
                    "rest_speed"):
            v = getattr(self, key)
            require(finite(v) and v >= 0, f"task.{key}", v, "must be a finite number >= 0")
        require(self.heightmap_n >= 1, "task.heightmap_n", self.heightmap_n, "must be >= 1")
        require(0.0 < self.curve_match_deg <= 180.0, "task.curve_match_deg", self.curve_match_deg, "in (0, 180]")
        require(self.friction is None or (finite(self.friction) and self.friction >= 0), "task.friction",
                self.friction, "null or >= 0")
        require(self.filmstrip_frames >= 0 and self.filmstrip_width > 0 and self.filmstrip_height > 0,
                "task.filmstrip_frames/width/height", (self.filmstrip_frames, self.filmstrip_width,
                                                       self.filmstrip_height), "frames >= 0, sizes > 0")


class GetupTask(PolicyTask):
    """Get-up motions that track height and torso-angle curves (003): PPO, C-VAE actions, eqs 2-9."""

    key_metrics: ClassVar[tuple[str, ...]] = ("success_rate", "r_task_mean", "task_return_rate")
    Config: ClassVar[type] = GetupConfig
    env_path: ClassVar[str] = "jt_tasks.getup.env:GetupEnv"

    @classmethod
    def check_run(cls, cfg: Any) -> None:
        """The humanoid (the curves and start poses come from its clips) and a prior for action=cvae/pvae."""
        require_humanoid_and_prior(cfg, "getup", "its curves and start poses come from the DeepMimic "
                                               "humanoid's get-up clips")

    def problem(self) -> SearchProblem:
        return SearchProblem(space=Space((Param("time_scale", 0.5, 2.0, float(self.params.time_scale)),)))

    def curve_set(self, time_scale: float) -> list:
        from jt_tasks.getup.curves import build_curves

        p = self.params
        return build_curves(list(p.curves), dict(p.authored), list(p.authored_durations) or None, p.n_control,
                            p.extraction, p.clamped, time_scale)

    def fallen(self, sim: dict) -> list:
        """The evaluation's rag-doll states (memoised per process)."""
        from jt_tasks.getup.initial import fallen_states

        p = self.params
        key = (repr(sim), p.n_fallen, p.fallen_seed, tuple(p.fallen_styles), p.drop_height, p.drop_perturb,
               p.ragdoll_kd, p.settle_max, p.rest_speed)
        if key not in _FALLEN:
            _FALLEN[key] = fallen_states(sim, p.n_fallen, p.fallen_seed, tuple(p.fallen_styles), p.drop_height,
                                         p.drop_perturb, p.ragdoll_kd, p.settle_max, p.rest_speed)
        return _FALLEN[key]

    def env_spec(self, point: dict[str, float]) -> Any:
        from jt_tasks.getup.env import GetupSpec

        p = self.params
        sim, action = self.character_groups()
        if p.friction is not None:
            sim["sim"] = {**(sim.get("sim") or {}), "friction": float(p.friction)}
        scale = float(point.get("time_scale", p.time_scale))
        reward = plain(group_of(self.cfg, "reward")) or {}
        return GetupSpec(curves=[c.to_dict() for c in self.curve_set(scale)], fallen=self.fallen(sim),
                         reward=dict(reward), natural_terms=tuple(p.natural_terms), t_stand=p.t_stand,
                         p_standing=p.p_standing, p_fallen=p.p_fallen, curve_match_deg=p.curve_match_deg,
                         r_task_min=p.r_task_min, sustain=p.sustain, head_grace=p.head_grace,
                         success_height=p.success_height, success_window=p.success_window,
                         heightmap_n=p.heightmap_n, heightmap_spacing=p.heightmap_spacing, sim=sim, action=action)

    # ------------------------------------------------------------------ evaluation (PolicyTask hooks)
    def training(self, spec: Any, ctx: EvalContext) -> Hooks:
        from jt_tasks.policy.train import agent_config
        from toolkit import plugins

        total = agent_config(group_of(self.cfg, "agent"), ctx.seed).total_samples
        node = group_of(self.cfg, "curriculum")
        cur = plugins.load("curriculum", str(node.name))(node) if node is not None and "name" in node else None
        extra: dict[str, Any] = cur.bind({}) if cur is not None else {}
        progress = ctx.progress

        def on_iteration(it: int, samples: int, stats: Any) -> dict[str, Any]:
            out = cur.on_iteration(it, samples, stats) if cur is not None else {}
            eps = getattr(stats, "episodes", []) or []
            fallen_eps = [e for e in eps if e.get("start_kind", 0.0) != 2.0]
            row = [float(samples)] + [float(np.mean([e.get(k, 0.0) for e in fallen_eps])) if fallen_eps else math.nan
                                      for k in HISTORY]
            prev = np.asarray(extra.get("getup_history", np.zeros((0, 1 + len(HISTORY)))), dtype=np.float64)
            extra["getup_history"] = np.vstack([prev.reshape(-1, 1 + len(HISTORY)), [row]])
            if progress is not None:
                progress(min(samples / max(total, 1), 1.0), f"success {row[1]:.2f}")
            return out

        return Hooks(on_iteration=on_iteration, extra=extra, state={"cur": cur})

    def final_options(self, env: Any) -> Optional[dict]:
        return {"kind": "clip", "curve": self.params.eval_curve}

    def eval_options(self, env: Any, n: int) -> list[dict]:
        """Reset options of the ``n`` deterministic evaluation get-ups: the rollout's, then the other
        clip curves' first poses and the rag-doll states in turn."""
        opts = [self.final_options(env)]
        others = [{"kind": "clip", "curve": c.name} for c in env.curves if c.clip and c.name != self.params.eval_curve]
        falls = [{"kind": "fallen", "fallen": i} for i in range(len(env.spec_.fallen))]
        pool = [o for pair in zip(others + [None] * len(falls), falls + [None] * len(others)) for o in pair if o]
        return (opts + pool * n)[:n] if pool else opts * n

    def record(self, env: Any) -> dict[str, Any]:
        out = super().record(env)
        m = env.measure()
        out["features"] = np.asarray(m["features"], float)
        out["targets"] = np.asarray(env.targets(env.t), float)
        return out

    def rollout_data(self, ro: dict, env: Any, spec: Any) -> tuple[dict, dict]:
        info = ro["info"]
        ro["log"] = list(env.log)
        data = {"features": ro["features"], "targets": ro["targets"],
                "curve_control": np.asarray(env.curve.control), "info": {k: float(v) for k, v in info.items()
                                                                        if isinstance(v, (int, float))}}
        if env.log:
            data["terms"] = {k: np.array([row[k] for row in env.log]) for k in env.log[0]}
        attrs = {"curve": env.curve.name, "duration": float(env.curve.duration), "start_kind": env.start_kind,
                 "return": float(ro["return"]), "reason": str(info.get("reason", ""))}
        return data, attrs

    def measure(self, spec: Any, ro: dict, trained: Any, hooks: Hooks, workdir: Path) -> Evaluation:
        from jt_tasks.policy.train import last_finite, return_curve, rollout
        from toolkit.rl.checkpoint import load_policy

        res, info, p = trained.result, ro["info"], self.params
        infos = [info]
        if p.eval_episodes > 1:
            model = load_policy(trained.checkpoint)
            env = self.env_class(spec, seed=0)
            try:
                for opts in self.eval_options(env, p.eval_episodes)[1:]:
                    infos.append(rollout(env, model, lambda e: {}, 0, 1, 1, opts)["info"])
            finally:
                env.close()
        metrics = {
            "success": float(info.get("success", 0.0)), "got_up": float(info.get("got_up", 0.0)),
            "success_rate": float(np.mean([i.get("success", 0.0) for i in infos])),
            "got_up_rate": float(np.mean([i.get("got_up", 0.0) for i in infos])),
            "r_task_mean": float(info.get("r_task_mean", 0.0)),
            "task_return_rate": float(np.mean([i.get("task_return_rate", 0.0) for i in infos])),
            "episode_time": float(info.get("episode_time", 0.0)), "mean_return": float(ro["return"]),
            "train_mean_return": last_finite(res.history.get("mean_return", [])),
            "samples": float(res.samples), "iterations": float(res.iterations),
            "samples_per_s": trained.samples_per_s, "train_wall_s": float(trained.wall_s),
        }
        for k in ("r_getup_height", "r_getup_torso", "r_getup_velocity", "r_getup_pose", "r_naturalness"):
            if f"{k}_mean" in info:
                metrics[f"{k}_mean"] = float(info[f"{k}_mean"])
        cur = hooks.state.get("cur")
        if cur is not None:
            if res.extra.get(cur.extra_key):
                cur.load_state(dict(res.extra[cur.extra_key]))
            metrics["terrain_level"] = float(cur.state()["level"])
        metrics = {k: v for k, v in metrics.items() if math.isfinite(v)}
        hist = np.asarray(res.extra.get("getup_history", np.zeros((0, 1 + len(HISTORY)))), dtype=np.float64)
        hist = hist.reshape(-1, 1 + len(HISTORY))
        history = {"mean_return": return_curve(trained)}
        for col, key in enumerate(HISTORY, start=1):
            history[f"train_{key}"] = [(int(r[0]), float(r[col])) for r in hist if math.isfinite(r[col])]
        return Evaluation(metrics=metrics, history=history)
