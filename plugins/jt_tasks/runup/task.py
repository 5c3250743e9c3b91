"""``task=runup``: train a DeepMimic run-up controller that ends in a desired take-off state (``000`` §6.1.1).

One evaluation = one run-up controller: PPO on ``RunupEnv`` (imitation of the DeepMimic run clip
plus the take-off task reward, eq 13 for ``kind: highjump``, eq 14 for ``kind: obstacle``) to the
``agent.total_samples`` budget, then the deterministic run-up from a fixed clip time. The searched
point is the target take-off features (high jump: ``omega_x``, ``omega_z``, ``v_z`` with
``omega_y`` = 3 rad/s fixed; obstacle: ``omega_x``, ``omega_y``, ``omega_z``); their ranges and
defaults are those of ``conf/task/highjump.yaml`` / ``obstacle.yaml`` unless ``task.ranges`` /
``task.target`` say otherwise (the high jump's ``alpha`` rotates the jump suite and plays no part
here). The simulated take-off state is saved as ``takeoff_state.h5`` (``jt_tasks.runup.state_file``)
for a jump task to start from. docs/runup.md.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar, Optional

import numpy as np

from toolkit.interfaces.searcher import Param, SearchProblem, Space
from toolkit.interfaces.task import EvalContext, Evaluation

from toolkit.policy.episodes import Rollout
from toolkit.policy.history import IterationHistory, measured, numbers
from toolkit.policy.task import Hooks, PolicyTask, require_character_and_prior

from jt_tasks.runup.config import RunupConfig

#: per-iteration means of the finished episodes (``extra["goal_history"]``), and their curves' names
HISTORY = ("r_goal", "r_imitation_mean", "took_off")
CURVES = {"r_goal": "goal_reward", "r_imitation_mean": "imitation_reward", "took_off": "takeoff_rate"}


def jump_task_box(kind: str) -> tuple[dict[str, tuple[float, float]], dict[str, float]]:
    """``(ranges, defaults)`` of the take-off features of the jump task ``kind`` (its search box,
    ``000`` Tables 3 / 4), from that task plugin's ``Config`` through the registry."""
    from toolkit import plugins

    c = plugins.load("task", kind).Config()
    return ({k: (float(v[0]), float(v[1])) for k, v in c.ranges.items()},
            {k: float(v) for k, v in c.takeoff.items()})


class RunupTask(PolicyTask):
    """DeepMimic run-up to a target take-off state (000 §6.1.1): imitation + take-off reward (eqs 13-14)."""

    key_metrics: ClassVar[tuple[str, ...]] = ("goal_reward", "imitation_reward", "mean_return")
    Config: ClassVar[type] = RunupConfig
    env_path: ClassVar[str] = "jt_tasks.runup.env:RunupEnv"
    action_inputs: ClassVar[frozenset[str]] = frozenset()  #: neither a phase nor a C-VAE condition
    #: its reward is its own (imitation + the take-off reward, eqs 13-14) and its difficulty fixed
    ignores_groups: ClassVar[tuple[str, ...]] = ("reward", "curriculum")

    @classmethod
    def check_run(cls, cfg: Any) -> None:
        """The run-up imitates the DeepMimic humanoid's run: character=humanoid (and a prior for
        the VAE action spaces)."""
        require_character_and_prior(cfg, "runup", "humanoid", "it imitates the DeepMimic humanoid's run")

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        from jt_tasks.runup.reward import GOAL_FEATURES

        if self.params.kind not in GOAL_FEATURES:
            from toolkit.errors import JtError

            raise JtError(f"task.kind={self.params.kind!r}: highjump (000 eq 13) or obstacle (000 eq 14)")
        self.feature_names = GOAL_FEATURES[self.params.kind]

    def box(self) -> tuple[dict[str, tuple[float, float]], dict[str, float]]:
        """``(ranges, defaults)`` of the target features, after ``task.ranges`` / ``task.target``."""
        ranges, defaults = jump_task_box(self.params.kind)
        ranges.update({k: (float(v[0]), float(v[1])) for k, v in (self.params.ranges or {}).items()})
        defaults.update({k: float(v) for k, v in (self.params.target or {}).items()})
        return ranges, defaults

    def problem(self) -> SearchProblem:
        r, d = self.box()
        fixed = self.params.point or {}
        names = [n for n in self.feature_names if n not in fixed]
        return SearchProblem(space=Space(tuple(Param(n, r[n][0], r[n][1], d.get(n)) for n in names)))

    def env_spec(self, point: dict[str, float]) -> Any:
        """The ``RunupSpec`` for target features ``point`` (missing ones: the defaults)."""
        from toolkit.policy.spec import spec_of
        from jt_tasks.runup.env import RunupSpec

        p = self.params
        _, defaults = self.box()
        feats = {**defaults, **{k: float(v) for k, v in point.items()},
                 **{k: float(v) for k, v in (p.point or {}).items()}}
        sim, action = self.character_groups()
        return spec_of(RunupSpec, p, target={k: float(feats[k]) for k in self.feature_names}, sim=sim, action=action)

    # ------------------------------------------------------------------ evaluation (PolicyTask hooks)
    def training(self, spec: Any, ctx: EvalContext) -> Any:
        """The per-iteration means of finished episodes' ``r_goal``, imitation reward and take-off
        rate (``extra["goal_history"]``)."""
        extra: dict[str, Any] = {}
        hist = IterationHistory(extra, "goal_history", HISTORY, self.sample_budget(ctx), ctx.progress,
                                shown=("r_goal", ".3f"))
        return Hooks(on_iteration=hist.on_iteration, extra=extra, state={"history": hist})

    def final_options(self, env: Any) -> Optional[dict]:
        """The take-off foot's mid-support, or ``eval_lead`` s before it: the run-up lasts
        ``n_strides`` whole cycles by default."""
        lead = self.params.eval_lead
        return {"time": float(env.ref.t_mid - (0.0 if lead is None else float(lead)))}

    def record(self, env: Any) -> dict[str, Any]:
        out = super().record(env)
        out["ref_root"] = env.ref.at(env.j0 + env.substeps_done).q[:7].copy()
        return out

    def rollout_data(self, ro: Rollout, env: Any, spec: Any) -> tuple[dict, dict]:
        info, notes = ro.info, ro.notes
        notes["q"], notes["qd"] = env.sim.state()
        notes["targets"] = dict(env.targets)
        notes["phase_time"] = float(env.ref.phase(env.clip_time) * env.ref.period)
        data = {"ref_root": ro.series["ref_root"], "r_imitation": np.array([t["imitation"] for t in env.terms_log]),
                "info": numbers(info)}
        attrs = {"kind": spec.kind, "targets": str(notes["targets"]), "return": float(ro.return_),
                 "reason": str(info.get("reason", ""))}
        return data, attrs

    def measure(self, spec: Any, ro: Rollout, trained: Any, hooks: Any, workdir: Path) -> Evaluation:
        from jt_tasks.takeoff.state_file import NAME, write_takeoff_state

        info, notes = ro.info, ro.notes
        if info.get("took_off"):
            achieved = {k[len("takeoff_"):]: float(v) for k, v in info.items() if k.startswith("takeoff_")}
            write_takeoff_state(workdir / NAME, notes["q"], notes["qd"], achieved, notes["targets"], spec.foot,
                                spec.kind, notes["phase_time"], float(info["r_goal"]))
        own = {"goal_reward": float(info.get("r_goal", 0.0)),
               "imitation_reward": float(info.get("r_imitation_mean", 0.0)),
               "took_off": float(info.get("took_off", 0.0)), "episode_time": float(info.get("episode_time", 0.0))}
        own.update({f"imitation_{k}": float(info.get(f"r_{k}_mean", 0.0)) for k in ("pose", "vel", "ee", "com")})
        own.update({k: v for k, v in info.items() if k.startswith(("takeoff_", "target_"))})
        metrics, history = measured(ro, trained, own, hooks.state["history"].curves(trained.result.extra, CURVES))
        if not info.get("took_off"):
            return Evaluation(metrics=metrics, failed=True, history=history,
                              reason=f"the deterministic run-up ended before the take-off: {info.get('reason', '')}")
        return Evaluation(metrics=metrics, history=history)

    def extra_artifacts(self, workdir: Path) -> list[str]:
        from jt_tasks.takeoff.state_file import NAME

        return [NAME] if (workdir / NAME).exists() else []
