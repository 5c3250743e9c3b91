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

import math
from pathlib import Path
from typing import Any, ClassVar, Optional

import numpy as np

from toolkit.interfaces.task import Evaluation

from toolkit.policy.episodes import Rollout
from toolkit.policy.history import measured, numbers
from toolkit.policy.task import Hooks, PolicyTask
from jt_tasks.spacetime import clips
from jt_tasks.spacetime.config import SpacetimeConfig


class SpacetimeTask(PolicyTask):
    """Spacetime bounds (002): PPO inside bounds around a clip, evaluated as 002 Table 1."""

    key_metrics: ClassVar[tuple[str, ...]] = ("survival_s", "survival_min_s", "survived", "samples", "train_mean_length")
    Config: ClassVar[type] = SpacetimeConfig
    env_path: ClassVar[str] = "jt_tasks.spacetime.env:SpacetimeEnv"
    #: ``jt play NAME``: the walk and run of ``experiment=laptop`` (Table 1's 20 s), a folder each
    skills: ClassVar[str] = "jt_tasks.spacetime.skills"
    #: its rewards are task.style's terms and the bounds; no curriculum drives it
    ignores_groups: ClassVar[tuple[str, ...]] = ("reward", "curriculum")
    action_inputs: ClassVar[frozenset[str]] = frozenset({"phase"})  #: the reference clip's phase
    #: no periodic Table 1 evaluation, a 1 s final one (a benchmark's)
    cheap_evaluation: ClassVar[dict[str, str]] = {"filmstrip_frames": "0", "eval_every": str(10 ** 9),
                                                  "eval_time_limit": "1.0"}
    #: ``jt study spacetime TOOL``: the analysis tools (``jt_tasks.spacetime.analysis``)
    studies: ClassVar[dict[str, str]] = {
        "survival": "jt_tasks.spacetime.analysis.survival_plot:main",
        "bounds": "jt_tasks.spacetime.analysis.bounds_study:main",
        "policy-bounds": "jt_tasks.spacetime.analysis.policy_bounds:main",
        "style": "jt_tasks.spacetime.analysis.style_study:main",
        "toy": "jt_tasks.spacetime.analysis.toy:main",
    }

    @classmethod
    def check_run(cls, cfg: Any) -> None:
        """The humanoid: its bounds, channels and reference clips are the DeepMimic humanoid's."""
        from toolkit.policy.task import require_character_and_prior

        require_character_and_prior(cfg, "spacetime", "humanoid", "its bounds and reference clips are the DeepMimic humanoid's")

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        from toolkit import plugins

        for t in self.params.style:  # an unknown term is a one-line error now, not in a worker
            plugins.load("reward", str(t["name"]))({k: v for k, v in dict(t).items() if k != "name"})

    def heading_axis(self) -> str:
        return clips.heading_axis(self.params.clip, self.params.heading_axis)

    def env_spec(self, point: dict[str, float]) -> Any:
        """The ``SpacetimeSpec`` of the task (no searched parameters: ``point`` is unused): the
        fields it shares with ``SpacetimeConfig`` copied (``policy.spec.spec_of``), the heading
        axis, bound widths and allowed contacts resolved, the simulator and action groups."""
        from toolkit.motion.skeletons import HUMANOID

        from toolkit.policy.spec import spec_of
        from jt_tasks.spacetime import bounds as bd
        from jt_tasks.spacetime.env import SpacetimeSpec
        from jt_tasks.spacetime.reference import resolve_clip

        p = self.params
        sim, action = self.character_groups()
        if str(action.get("name")) == "ffc_fbc":
            action["clip"] = resolve_clip(p.clip)  # the FFC plays the task's clip
        com = list(p.com_width) if isinstance(p.com_width, (list, tuple)) else p.com_width
        w = bd.widths(HUMANOID, com, p.orientation_width, p.end_effector_width, p.widths)
        names = None if p.allowed_contacts is None else list(p.allowed_contacts)
        allowed = clips.allowed_links(HUMANOID, p.clip, names)
        return spec_of(SpacetimeSpec, p, heading_axis=self.heading_axis(), widths=[float(x) for x in w],
                       width_table=bd.width_table(HUMANOID, w, p.width_table).tolist(),
                       train_allowed=allowed, eval_allowed=allowed,
                       sampling={"evolution": bool(p.evolution)}, sim=sim, action=action)

    def training(self, spec: Any, ctx: Any) -> Hooks:
        """PPO's ``on_iteration`` (``training.SpacetimeTraining``): eq 11 start weights and eq 12
        buffers (``StartSampler``) every iteration, sent to the envs as ``start_sampling``, and
        Table 1's evaluation every ``eval_every`` iterations; their state rides in ``extra``."""
        import functools

        from jt_tasks.spacetime.sampling import StartSampler
        from jt_tasks.spacetime.training import SpacetimeTraining

        params = self.params.sampling_params()
        extra: dict[str, Any] = {}
        sampler = StartSampler(params, extra, ctx.seed) if (params.importance_sampling or params.evolution) else None
        hook = SpacetimeTraining(sampler, functools.partial(self.env_class, spec, seed=ctx.seed),
                                 self.final_options(None), int(self.params.eval_every), extra, ctx.progress,
                                 self.sample_budget(ctx), int(self.params.eval_starts))
        return Hooks(on_iteration=hook, extra=extra, state={"sampler": sampler, "training": hook})

    # ------------------------------------------------------------------ evaluation (PolicyTask hooks)
    def final_options(self, env: Any) -> Optional[dict]:
        return {"phase": float(self.params.eval_phase), "evaluate": True}

    def play_options(self, env: Any, start: Optional[str] = None) -> Optional[dict]:
        """``jt play --start X``: the clip phase in [0, 1] the replay starts at (default ``task.eval_phase``)."""
        options = dict(self.final_options(env) or {})
        if start is not None:
            try:
                phase = float(start)
            except ValueError:
                phase = math.nan
            if not 0.0 <= phase <= 1.0:
                from toolkit.errors import JtError

                raise JtError(f"--start={start}: task=spacetime starts at a clip phase in [0, 1]")
            options["phase"] = phase
        return options

    def play_summary(self, env: Any, ro: Rollout) -> tuple[dict[str, Any], str]:
        """Table 1's measure of one replay: the seconds survived from its start phase and whether
        the episode ran to its end; ``{"survival_s", "survived", "start_phase"}``."""
        _, tail = super().play_summary(env, ro)
        t = float(ro.info.get("survival_s", env.t))
        survived = bool(ro.info.get("time_out", 0.0))
        phase = float(env.phase0)
        reason = str(ro.info.get("reason", "") or "")
        if survived:
            head = f"survived {t:.2f} s (the whole episode)"
        elif reason:
            head = f"fell at {t:.2f} s ({reason})"
        else:
            head = f"still up at {t:.2f} s"
        measure = {"survival_s": round(t, 2), "survived": survived, "start_phase": round(phase, 3)}
        return measure, f"{Path(str(env.spec_.clip)).stem}: {head} from clip phase {phase:.2f} ({tail})"

    def rollout_data(self, ro: Rollout, env: Any, spec: Any) -> tuple[dict, dict]:
        from jt_tasks.spacetime.artifacts import com_height_data

        from jt_tasks.spacetime.artifacts import reference_bodies, style_measures

        info, notes = ro.info, ro.notes
        notes["com_height"] = com_height_data(env, ro.time, ro.com)
        notes["style"] = {"policy": style_measures(env.eval_bodies, env.masses, env.control_hz),  # 002 §3.3
                          "reference": style_measures(reference_bodies(env, ro.time), env.masses, env.control_hz)}
        if ro.frames:  # the reference at the same clip times, for motion_vs_reference.gif
            from jt_tasks.spacetime.artifacts import reference_frames

            h, w = np.asarray(ro.frames[0]).shape[:2]
            notes["reference_frames"] = reference_frames(env, ro.time, w, h)
            notes["fps"] = float(env.control_hz)
        data = {"info": numbers(info), "phase": notes["com_height"]["phase"]}
        attrs = {"clip": spec.clip, "termination": spec.termination, "return": float(ro.return_),
                 "reason": str(info.get("reason", "")), "widths": str(list(spec.widths)),
                 **{f"{who}_{k}": v for who, m in notes["style"].items() for k, v in m.items()}}
        return data, attrs

    def measure(self, spec: Any, ro: Rollout, trained: Any, hooks: Any, workdir: Path) -> Evaluation:
        from toolkit.policy.train import last_finite, samples_axis

        res, info, notes = trained.result, ro.info, ro.notes
        survival = float(info["survival_s"])  # every evaluation episode ends with it
        lengths = res.history.get("mean_length", [])
        own = {"survival_s": survival, "survival_steps": float(ro.steps),
               "survived": float(bool(info.get("time_out", 0.0))), "train_mean_length": last_finite(lengths)}
        for who, m in notes.get("style", {}).items():  # style measures vs the reference's (002 §3.3, §5.3)
            prefix = "style" if who == "policy" else "ref"
            own.update({f"{prefix}_energy": m["energy"], f"{prefix}_volume": m["volume"]})
        metrics, history = measured(ro, trained, own, {
            "mean_length": [(s, float(v)) for s, v in zip(samples_axis(trained), lengths) if math.isfinite(v)]})
        if "com_height" in notes:
            from jt_tasks.spacetime.artifacts import plot_com_bounds

            plot_com_bounds(notes["com_height"], Path(workdir) / "com_bounds.png",
                            f"{Path(str(spec.clip)).stem}: CoM height vs phase, final rollout (002 Fig. 5)")
        if notes.get("reference_frames"):
            from jt_tasks.spacetime.artifacts import write_motion_vs_reference

            write_motion_vs_reference(workdir, ro.frames, notes["reference_frames"], notes["fps"])
        hook = hooks.state.get("training")
        if hook is not None and hook.n_starts > 1:  # the final policy from every start phase
            mean, share, worst = hook.evaluate(trained.result.model)
            metrics.update({"survival_first_s": survival, "survival_s": mean, "survival_min_s": worst,
                            "survived": share})
        rows = hook.history() if hook is not None else np.zeros((0, 4))
        if len(rows):
            from jt_tasks.spacetime.training import samples_to_20s

            history.update(hook.curves({"survival_s": "survival_s", "survival_min_s": "survival_min_s"}))
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
