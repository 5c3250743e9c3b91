"""``task=spacetime``: learn a motor skill with spacetime bounds (``002``, Ma et al. 2021).

One evaluation = one motion: PPO (``agent=ppo_spacetime``, 002 §5) on ``SpacetimeEnv`` with the
FFC + FBC action (``action=ffc_fbc``, 002 §4.2) and reference state initialisation, terminated
early by the spacetime bounds (``termination: bounds``, 002 §3.2 eq 2, reward 1 times the style
terms) or, as the DeepMimic baseline of 002 Table 1, by a forbidden ground contact with
DeepMimic's imitation reward (``termination: contact``). Then the deterministic policy is
evaluated as in 002 Table 1: bounds off, up to ``eval_time_limit`` (20 s), failing only on a
forbidden ground contact; the metric is ``survival_s``. After every PPO iteration the start
distribution adapts (002 §4.3, ``sampling.StartSampler``): start phases by eq 11 (on with bounds)
and, with ``evolution``, start states from eq 12's per-segment buffers; the distribution per
iteration is logged (``start_sampling.h5`` / ``.png``). ``mix`` gives eq 13's reward. The final
rollout also gives ``com_bounds.png`` (Fig. 5) and ``motion_vs_reference.gif`` (the policy
beside the reference at the same clip times). docs/spacetime.md.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any, ClassVar, Optional

import numpy as np

from toolkit.config import group_of
from toolkit.interfaces.task import Evaluation

from jt_tasks.policy.task import Hooks, PolicyConfig, PolicyTask

#: the clips whose heading is taken from the root's z axis (authors' code; research notes)
Z_HEADING = ("backflip", "roll", "crawl")
FEET = ("right_ankle", "left_ankle")
HANDS = ("right_wrist", "left_wrist")
#: links allowed on the ground per clip (research notes: the authors' evaluation); others: the feet
ALLOWED_CONTACTS: dict[str, Any] = {
    "cartwheel": FEET + HANDS,
    "crawl": "all but root, chest, neck",
    "roll": "all",
    "getup_facedown": "all",
    "getup_faceup": "all",
}


def allowed_links(skeleton: Any, clip: str, names: Optional[list] = None) -> tuple[int, ...]:
    """Link indices allowed on the ground: ``names`` (link names, ``base``; ``["all"]``), else the
    clip's entry of ``ALLOWED_CONTACTS`` (feet by default)."""
    links = ["base"] + list(skeleton.links)
    index = {n: i - 1 for i, n in enumerate(links)}  # base = -1
    if names is None:
        entry = ALLOWED_CONTACTS.get(clip, FEET)
        if entry == "all":
            names = links
        elif isinstance(entry, str):  # "all but ..."
            names = [n for n in links if n not in ("base", "root", "chest", "neck")]
        else:
            names = list(entry)
    elif list(names) == ["all"]:
        names = links
    return tuple(sorted(index[str(n)] for n in names))


@dataclasses.dataclass
class SpacetimeConfig(PolicyConfig):
    """The ``task`` group of ``task=spacetime`` (every default with its source)."""

    name: str = "spacetime"
    """Registry name."""
    clip: str = "run"
    """Reference motion: a pybullet_data humanoid clip (humanoid3d_<clip>.txt) or a path (002 Table 1 motions; ours: run)."""
    loop: Optional[bool] = None
    """Override the clip's Loop flag; null: the file's (every shipped clip wraps; 002 §5: jump and backflip end, ours to choose)."""
    heading_axis: Optional[str] = None
    """Root axis whose ground projection is the heading: x or z; null: z for backflip, roll, crawl, else x (authors' code)."""
    termination: str = "bounds"
    """Bounds: spacetime-bound early termination (002 §3.2 eq 2); contact: the DeepMimic baseline (002 Table 1)."""
    com_width: Any = 0.2
    """M, CoM x/y/z channels, one number or [x, y, z] (002 §5.1; the authors' code: [0.3, 0.2, 0.3])."""
    orientation_width: Optional[float] = 0.7
    """Rad, root and joint angle channels (002 §5.1); null: off."""
    end_effector_width: Optional[float] = 0.5
    """M, ankle and wrist channels (002 §5.1); null: off."""
    widths: dict = dataclasses.field(default_factory=dict)
    """{channel or group (com, orientation, end_effector): width} overrides; null or .inf switches a channel off (002 §5.3.1 style runs)."""
    width_table: list = dataclasses.field(default_factory=list)
    """Phase table: K rows evenly over phase [0, 1], each {channel or group: width} over the widths above (or 22 numbers), linearly interpolated at the clip's phase mod 1 (authors' code); []: the constant widths (002 §5.1; every table the authors ship is constant)."""
    time_limit: float = 20.0
    """S, training episodes are truncated (bootstrapped) here (002 §5.1)."""
    hold_s: float = 0.5
    """S, a non-looping clip is extended by holding its last frame this long (authors' code)."""
    init_phase: Optional[float] = None
    """Start phase of training episodes; null: uniform over [0, 1) (reference state initialisation, 002 §4.2 / DeepMimic)."""
    ground_clearance: float = 0.001
    """M, a start that penetrates the ground is lifted so that its lowest point is this high; other starts and the reference are the clip's own (authors' code: 0.001)."""
    cycle_turn: bool = True
    """A looping clip's next cycle carries on its heading change (the walk turns 0.12 rad per cycle), so the reference is where a character tracking the clip goes (ours; the authors' code shifts each cycle by the root's position change only: the heading snaps back at every seam)."""
    root_orientation: str = "world"
    """Frame of the root's orientation in the observation: world, the reference cycle's frame (the world frame when cycles do not turn), so the policy sees the heading the bounds hold (002 §4.1: every kinematic quantity in the motion-direction frame except the root orientation; authors' code: use_global_root_ori); heading: in the root's own heading frame like the other links (jt before 2026-12, which hides the heading drift that ends the walk by its lateral CoM bound)."""
    ffc_lead: float = 0.0
    """Control steps by which the FFC's reference pose leads the control step's start (002 and the authors' code: 0, the pose at the start of the step held over its substeps)."""
    ffc_velocity: bool = False
    """The reference's joint velocities at the FFC's time as the PD target velocity (002 and the authors' code: zero target velocity)."""
    eval_starts: int = 4
    """Start phases of Table 1's evaluation, eval_phase + k / eval_starts; survival_s is their mean, survival_min_s the worst (authors' code: the mean over several episodes from random phases; ours: evenly spread, deterministic)."""
    style: list = dataclasses.field(default_factory=list)
    """Style reward terms ([{name: energy, ...}], jt.rewards), multiplied into the reward of 1 (002 §3.3 eqs 4-8)."""
    eval_phase: float = 0.0
    """Start phase of the deterministic evaluation (ours)."""
    eval_time_limit: float = 20.0
    """S, the evaluation asks for this long without falling (002 Table 1: 20 s)."""
    allowed_contacts: Optional[list] = None
    """Link names allowed on the ground in the evaluation and the contact arm (["all"]: any); null: per clip (authors' code: walk feet, cartwheel feet and hands, crawl all but root/chest/neck, roll all)."""
    filmstrip_frames: int = 4
    """Frames of the final rollout's filmstrip (ours)."""
    eval_every: int = 10
    """PPO iterations between evaluations during training, for survival_s vs samples and samples_to_20s (authors' code: every 10; 0: only the final one)."""
    mix: Optional[float] = None
    """Eq 13 weight w_s: reward (1 - w_s) imitation + w_s style in either arm (002 §5.3.1 Table 2: 0.5-0.8); null: survival x style / imitation."""
    importance_sampling: Optional[bool] = None
    """Start segments by eq 11 (002 §4.3.1); null: on with termination=bounds, off (uniform RSI, DeepMimic) with contact."""
    n_segments: int = 10
    """Segments of the clip for eq 11 and eq 12 (002 §4.3.1; authors' code: 10 for the Table 1 motions)."""
    is_uniform: float = 0.2
    """U of eq 11, the share of uniformly drawn segments (002 §4.3.1)."""
    is_average: float = 0.99
    """Running-average factor of each segment's start targets w_k (authors' code; 002 §4.3.1: "average")."""
    is_reading: str = "paper"
    """Eq 11 temperature: paper v = (max - min) / 3 (002 §4.3.1); code v = (max - min) + 0.01 (authors' code)."""
    evolution: bool = False
    """Initial-state evolution, eq 12 (002 §4.3.2, for low-quality references; authors' code: off for every Table 1 motion)."""
    evolution_size: int = 200
    """M, states per segment buffer (002 §4.3.2 leaves m open; authors' code: 200, 100 Atlas, 20 long dances)."""
    evolution_reading: str = "paper"
    """Eq 12: paper exp(-w/v), v = max - min, favours low returns (002 §4.3.2); code exp(3 (w - max) / (gap + 0.01)), favours high, old values x 0.95 (authors' code)."""
    evolution_share: Optional[float] = None
    """Share of starts from a buffer state; null: 1 with the paper reading (002 §4.3.2: starts are drawn from the buffers), 0.8 with the code's (authors' code)."""
    evolution_warmup: Optional[int] = None
    """Iterations before buffer starts begin; null: 0 with the paper reading (002 §4.3.2), 400 with the code's (authors' code)."""

    def sampling_params(self, termination: Optional[str] = None):
        """The ``SamplingParams`` these fields give (readings' defaults filled in)."""
        from jt_tasks.spacetime.sampling import SamplingParams

        code = self.evolution_reading == "code"
        term = self.termination if termination is None else termination
        return SamplingParams(
            importance=(term == "bounds") if self.importance_sampling is None else bool(self.importance_sampling),
            n_segments=int(self.n_segments), uniform=float(self.is_uniform), average=float(self.is_average),
            is_reading=str(self.is_reading), evolution=bool(self.evolution), buffer_size=int(self.evolution_size),
            share=(0.8 if code else 1.0) if self.evolution_share is None else float(self.evolution_share),
            warmup=(400 if code else 0) if self.evolution_warmup is None else int(self.evolution_warmup),
            evolution_reading=str(self.evolution_reading), decay=0.95 if code else 1.0)

    def check(self) -> None:
        """One-line ``JtError`` for a bad clip, width, channel, heading axis or range."""
        from toolkit.motion.skeletons import HUMANOID
        from toolkit.schema import finite, require

        from jt_tasks.spacetime import bounds as bd
        from jt_tasks.spacetime.reference import load_humanoid_clip

        load_humanoid_clip(self.clip)
        require(self.heading_axis in (None, "x", "z"), "task.heading_axis", self.heading_axis, "x or z (null: per clip)")
        require(self.root_orientation in ("world", "heading"), "task.root_orientation", self.root_orientation,
                "world or heading")
        require(self.termination in ("bounds", "contact"), "task.termination", self.termination,
                "bounds (002 §3.2) or contact (the DeepMimic baseline)")
        com = list(self.com_width) if isinstance(self.com_width, (list, tuple)) else self.com_width
        base = bd.widths(HUMANOID, com, self.orientation_width, self.end_effector_width, self.widths)
        bd.width_table(HUMANOID, base, self.width_table)
        for key in ("time_limit", "hold_s", "eval_time_limit"):
            v = getattr(self, key)
            require(finite(v) and (v > 0 or (key == "hold_s" and v >= 0)), f"task.{key}", v, "must be a finite number > 0")
        for key in ("init_phase", "eval_phase"):
            v = getattr(self, key)
            require(v is None or (finite(v) and 0.0 <= v <= 1.0), f"task.{key}", v, "a phase in [0, 1]")
        require(finite(self.ground_clearance) and self.ground_clearance >= 0, "task.ground_clearance",
                self.ground_clearance, "a finite number >= 0 (m)")
        require(finite(self.ffc_lead) and self.ffc_lead >= 0, "task.ffc_lead", self.ffc_lead,
                "a number of control steps >= 0")
        require(int(self.eval_starts) >= 1, "task.eval_starts", self.eval_starts, "an integer >= 1")
        if self.allowed_contacts is not None:
            known = {"base", "all", *HUMANOID.links}
            bad = [n for n in self.allowed_contacts if str(n) not in known]
            require(not bad, "task.allowed_contacts", bad, f"unknown link(s); links: {', '.join(sorted(known))}")
        for t in self.style:
            require(isinstance(t, dict) and "name" in t, "task.style", t, "a list of {name: <jt.rewards term>, ...}")
        require(self.mix is None or (finite(self.mix) and 0.0 <= self.mix <= 1.0), "task.mix", self.mix,
                "null or a weight w_s in [0, 1] (002 eq 13)")
        for key in ("is_reading", "evolution_reading"):
            require(getattr(self, key) in ("paper", "code"), f"task.{key}", getattr(self, key), "paper or code")
        require(int(self.n_segments) >= 1 and int(self.evolution_size) >= 1, "task.n_segments/evolution_size",
                (self.n_segments, self.evolution_size), "integers >= 1")
        for key in ("is_uniform", "is_average", "evolution_share"):
            v = getattr(self, key)
            require(v is None or (finite(v) and 0.0 <= v <= 1.0), f"task.{key}", v, "a number in [0, 1]")
        require(self.evolution_warmup is None or int(self.evolution_warmup) >= 0, "task.evolution_warmup",
                self.evolution_warmup, "null or an iteration count >= 0")
        require(int(self.eval_every) >= 0, "task.eval_every", self.eval_every, "an iteration count >= 0 (0: off)")
        require(self.filmstrip_frames >= 0 and self.filmstrip_width > 0 and self.filmstrip_height > 0,
                "task.filmstrip_frames/width/height", (self.filmstrip_frames, self.filmstrip_width,
                                                       self.filmstrip_height), "frames >= 0, sizes > 0")


class SpacetimeTask(PolicyTask):
    """Spacetime bounds (002): PPO inside bounds around a clip, evaluated as 002 Table 1."""

    key_metrics: ClassVar[tuple[str, ...]] = ("survival_s", "survived", "samples", "train_mean_length")
    Config: ClassVar[type] = SpacetimeConfig
    env_path: ClassVar[str] = "jt_tasks.spacetime.env:SpacetimeEnv"

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        from toolkit import plugins

        for t in self.params.style:  # an unknown term is a one-line error now, not in a worker
            plugins.load("reward", str(t["name"]))({k: v for k, v in dict(t).items() if k != "name"})

    def heading_axis(self) -> str:
        p = self.params
        if p.heading_axis is not None:
            return str(p.heading_axis)
        return "z" if Path(str(p.clip)).stem.replace("humanoid3d_", "") in Z_HEADING else "x"

    def env_spec(self, point: dict[str, float]) -> Any:
        """The ``SpacetimeSpec`` of the task (no searched parameters: ``point`` is unused)."""
        from toolkit.motion.skeletons import HUMANOID

        from jt_tasks.spacetime import bounds as bd
        from jt_tasks.spacetime.env import SpacetimeSpec
        from jt_tasks.spacetime.reference import resolve_clip

        p = self.params
        sim, action = self.character_groups()
        if str(action.get("name")) == "ffc_fbc":
            action["clip"] = resolve_clip(p.clip)  # the FFC plays the task's clip
        com = list(p.com_width) if isinstance(p.com_width, (list, tuple)) else p.com_width
        w = bd.widths(HUMANOID, com, p.orientation_width, p.end_effector_width, p.widths)
        clip = Path(str(p.clip)).stem.replace("humanoid3d_", "")
        allowed = allowed_links(HUMANOID, clip, None if p.allowed_contacts is None else list(p.allowed_contacts))
        return SpacetimeSpec(clip=str(p.clip), heading_axis=self.heading_axis(), loop=p.loop,
                             ground_clearance=float(p.ground_clearance), cycle_turn=bool(p.cycle_turn),
                             root_orientation=str(p.root_orientation),
                             ffc_lead=float(p.ffc_lead), ffc_velocity=bool(p.ffc_velocity), termination=p.termination,
                             widths=[float(x) for x in w],
                             width_table=bd.width_table(HUMANOID, w, p.width_table).tolist(), time_limit=float(p.time_limit), hold_s=float(p.hold_s),
                             init_phase=p.init_phase, train_allowed=allowed, eval_allowed=allowed,
                             eval_time_limit=float(p.eval_time_limit), style=[dict(t) for t in p.style],
                             mix=None if p.mix is None else float(p.mix),
                             sampling={"evolution": bool(p.evolution)}, sim=sim, action=action)

    def training(self, spec: Any, ctx: Any) -> Hooks:
        """PPO's ``on_iteration`` (``training.SpacetimeTraining``): eq 11 start weights and eq 12
        buffers (``StartSampler``) every iteration, sent to the envs as ``start_sampling``, and
        Table 1's evaluation every ``eval_every`` iterations; their state rides in ``extra``."""
        import functools

        from jt_tasks.policy.train import agent_config
        from jt_tasks.spacetime.sampling import StartSampler
        from jt_tasks.spacetime.training import SpacetimeTraining

        params = self.params.sampling_params()
        extra: dict[str, Any] = {}
        sampler = StartSampler(params, extra, ctx.seed) if (params.importance or params.evolution) else None
        total = agent_config(group_of(self.cfg, "agent"), ctx.seed).total_samples
        hook = SpacetimeTraining(sampler, functools.partial(self.env_class, spec, seed=ctx.seed),
                                 self.final_options(None), int(self.params.eval_every), extra, ctx.progress, total,
                                 int(self.params.eval_starts))
        return Hooks(on_iteration=hook, extra=extra, state={"sampler": sampler, "training": hook})

    # ------------------------------------------------------------------ evaluation (PolicyTask hooks)
    def final_options(self, env: Any) -> Optional[dict]:
        return {"phase": float(self.params.eval_phase), "evaluate": True}

    def rollout_data(self, ro: dict, env: Any, spec: Any) -> tuple[dict, dict]:
        from jt_tasks.spacetime.artifacts import com_height_data

        from jt_tasks.spacetime.artifacts import reference_bodies, style_measures

        info = ro["info"]
        ro["com_height"] = com_height_data(env, ro["time"], ro["com"])
        ro["style"] = {"policy": style_measures(env.eval_bodies, env.masses, env.control_hz),  # 002 §3.3
                       "reference": style_measures(reference_bodies(env, ro["time"]), env.masses, env.control_hz)}
        if ro["frames"]:  # the reference at the same clip times, for motion_vs_reference.gif
            from jt_tasks.spacetime.artifacts import reference_frames

            h, w = np.asarray(ro["frames"][0]).shape[:2]
            ro["reference_frames"] = reference_frames(env, ro["time"], w, h)
            ro["fps"] = float(env.control_hz)
        data = {"info": {k: float(v) for k, v in info.items() if isinstance(v, (int, float))},
                "phase": ro["com_height"]["phase"]}
        attrs = {"clip": spec.clip, "termination": spec.termination, "return": float(ro["return"]),
                 "reason": str(info.get("reason", "")), "widths": str(list(spec.widths)),
                 **{f"{who}_{k}": v for who, m in ro["style"].items() for k, v in m.items()}}
        return data, attrs

    def measure(self, spec: Any, ro: dict, trained: Any, hooks: Any, workdir: Path) -> Evaluation:
        from jt_tasks.policy.train import last_finite, return_curve, samples_axis

        res, info = trained.result, ro["info"]
        steps = int(ro["steps"])
        survival = float(info["survival_s"])  # every evaluation episode ends with it
        lengths = res.history.get("mean_length", [])
        metrics = {
            "survival_s": survival,
            "survival_steps": float(steps),
            "survived": float(bool(info.get("time_out", 0.0))),
            "mean_return": float(ro["return"]),
            "train_mean_return": last_finite(res.history.get("mean_return", [])),
            "train_mean_length": last_finite(lengths),
            "samples": float(res.samples), "iterations": float(res.iterations),
            "samples_per_s": trained.samples_per_s, "train_wall_s": float(trained.wall_s),
        }
        for who, m in ro.get("style", {}).items():  # style measures vs the reference's (002 §3.3, §5.3)
            prefix = "style" if who == "policy" else "ref"
            metrics.update({f"{prefix}_energy": m["energy"], f"{prefix}_volume": m["volume"]})
        metrics = {k: v for k, v in metrics.items() if math.isfinite(v)}
        history = {"mean_return": return_curve(trained),
                   "mean_length": [(s, float(v)) for s, v in zip(samples_axis(trained), lengths) if math.isfinite(v)]}
        if "com_height" in ro:
            from jt_tasks.spacetime.artifacts import plot_com_bounds

            plot_com_bounds(ro["com_height"], Path(workdir) / "com_bounds.png",
                            f"{Path(str(spec.clip)).stem}: CoM height vs phase, final rollout (002 Fig. 5)")
        if ro.get("reference_frames"):
            from jt_tasks.spacetime.artifacts import write_motion_vs_reference

            write_motion_vs_reference(workdir, ro["frames"], ro["reference_frames"], ro["fps"])
        hook = hooks.state.get("training")
        if hook is not None and hook.n_starts > 1:  # the final policy from every start phase
            mean, share, worst = hook.evaluate(trained.result.model)
            metrics.update({"survival_first_s": survival, "survival_s": mean, "survival_min_s": worst,
                            "survived": share})
        rows = hook.history() if hook is not None else np.zeros((0, 4))
        if len(rows):
            from jt_tasks.spacetime.training import samples_to_20s

            history["survival_s"] = [(int(r[0]), float(r[1])) for r in rows]
            history["survival_min_s"] = [(int(r[0]), float(r[3])) for r in rows]
            reached = samples_to_20s(rows)
            if reached is not None:
                metrics["samples_to_20s"] = reached
        sampler = hooks.state.get("sampler")
        h = sampler.history() if sampler is not None else None
        if h is not None:
            from jt_tasks.spacetime.artifacts import write_start_sampling

            write_start_sampling(workdir, h)
            history["is_max_prob"] = [(int(x), float(p.max())) for x, p in zip(h["samples"], h["probs"])]
            metrics["is_max_prob"] = float(h["probs"][-1].max())
            metrics["is_entropy"] = float(-(h["probs"][-1] * np.log(h["probs"][-1])).sum())
        return Evaluation(metrics=metrics, history=history)

    def extra_artifacts(self, workdir: Path) -> list[str]:
        names = ("start_sampling.h5", "start_sampling.png", "com_bounds.png", "motion_vs_reference.gif")
        return [n for n in names if (Path(workdir) / n).exists()]
