"""``PolicyTask``: a task whose evaluation trains a policy with PPO on a ``CharacterEnv``.

``evaluate`` is the same for every policy task: build the env spec of the searched point, train
(``policy.train.train_policy``, resumable from ``ppo.h5``), roll the deterministic policy out once,
write ``rollout.h5``, ``filmstrip.png`` and ``motion.gif``, and return the task's metrics with the
training curves. A task subclass says only what is its own:

* ``Config`` (its ``task`` group, defaults with their sources) and ``env_path`` (its env class);
* ``env_spec(point)``: the picklable spec of its environment (``character_groups()`` gives the
  simulator, SPD, character and action groups as plain dicts);
* optionally ``training(spec, ctx)``: PPO hooks (a curriculum, Stage 2's warm start ...);
  ``final_env(env, hooks)`` / ``final_options(env)``: the deterministic rollout's set-up;
  ``record(env)``: what to log per control step; ``rollout_data(ro, env, spec)``: what
  ``rollout.h5`` holds besides ``time``, ``root`` and ``com``; and ``measure(...)``: the metrics.
  The hooks read the deterministic episode as a ``policy.episodes.Rollout`` (``ro``).
* for ``jt play`` (``toolkit.play``): ``play_summary(env, ro)`` (what a replay reached, the
  measure a shipped skill documents, and its line), ``play_options(env, start)`` (``--start``)
  and ``replay_attrs(env_attrs, metrics)`` (the env attributes of a run's replay).

What the hooks of every task share is in ``toolkit.policy`` too: ``sample_budget(ctx)`` (the
evaluation's PPO budget, for progress fractions), ``episodes.rollout`` / ``episodes.opened_env``
(one more deterministic episode, an env closed however the block ends),
``periodic.PeriodicEvaluation`` (an evaluation every few iterations, kept in ``ppo.h5``),
``history.IterationHistory`` (a per-iteration training curve) and ``history.measured`` (the
metrics and curves every task reports beside its own).

With ``task.evaluate=NAME|RUN|PATH`` nothing is trained: ``evaluate`` takes the policy that
``toolkit.policy.trained`` resolves and copies into the evaluation's folder, and measures it as
above. ``require_character_and_prior`` (for a task's ``check_run``: its character, its action
space's prior, and that policy's fit) refuses, before a run opens, a run that cannot work.

A task constructed without a config (``Task(None)``) composes its own defaults
(``jt run task=<name>``), so every group it reads exists.
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Any, Callable, ClassVar, Optional

from toolkit.config import group_of, plain, task_params
from toolkit.interfaces.task import EvalContext, Evaluation, Task

from toolkit.policy import train as tr
from toolkit.policy.episodes import Rollout, opened_env, rollout
from toolkit.policy.history import time_breakdown
from toolkit.policy.trained import (adopt_checkpoint, adopt_skill, check_policy_fits, trained_policy, trained_skill,
                                    warm_policy)


def require_character_and_prior(cfg: Any, task: str, character: str, why: str) -> None:
    """For ``Task.check_run``: ``character=<character>`` (``why`` says what the task takes from
    it) and, for an action space that decodes through a trained prior (``needs_prior``), a prior
    named; one ``JtError`` line each."""
    from toolkit import plugins
    from toolkit.errors import JtError, UnknownPlugin

    got = str(group_of(group_of(cfg, "character") or {}, "name") or "")
    if got != character:
        raise JtError(f"task={task} needs character={character} ({why}), got character={got or '(none)'}")
    action = group_of(cfg, "action")
    name = str(group_of(action, "name") or "") if action is not None else ""
    try:
        needs_prior = bool(name) and bool(getattr(plugins.load("action", name), "needs_prior", False))
    except UnknownPlugin:  # composition names the valid action spaces
        needs_prior = False
    prior = str(group_of(action, "prior") or "").strip() if needs_prior else ""
    if needs_prior and not prior:
        raise JtError(f"action={name} needs a trained prior: action.prior=<run id | folder | prior.h5>; "
                      f"train one with: jt run task=pose_prior action={name} (or use action=raw)")
    if prior and prior != "auto":  # read and checked before the run opens (auto: found or trained by the runner)
        from toolkit.priors.io import load_prior

        store = str(group_of(action, "store") or "").strip() or group_of(cfg, "store")  # action.store first
        load_prior(prior, None if store is None else str(store), name)  # format, kind, shapes: one line each
    path = trained_policy(cfg, task)  # task.evaluate names a trained policy that exists
    if path is not None and prior != "auto":  # auto: checked again once the runner has found it
        check_policy_fits(cfg, task, path)
    warm = warm_policy(cfg, task)  # task.warm_start names a full checkpoint of this environment's sizes
    if warm is not None and prior != "auto":
        check_policy_fits(cfg, task, warm, "warm_start")


@dataclasses.dataclass
class PolicyConfig:
    """What every policy task's ``task`` group has: the final rollout's pictures. A task's
    ``Config`` derives from it (its own fields follow)."""

    filmstrip_frames: int = 8
    """Frames of the final deterministic rollout's filmstrip (0: no pictures); the GIF has every
    control step's frame."""
    filmstrip_width: int = 320
    """px per frame."""
    filmstrip_height: int = 240
    """px."""
    evaluate: str = ""
    """A trained policy to measure instead of training one: a run id (its best evaluation), a
    folder or a ``ppo.h5``, or a shipped skill's name (``jt play`` lists them: its overrides
    compose under the command line's, its environment attributes are set, and the run's
    environment must be the skill's). Its policy is rolled out and measured with this run's
    settings and no sample is collected (jt; e.g. ``003`` Table 1 of a policy trained earlier)."""
    warm_start: str = ""
    """A trained policy that training starts from instead of fresh networks: a run id (its best
    evaluation), a folder or a ``ppo.h5`` (its policy, value network and observation normaliser;
    fresh optimiser, counters and budget; jt, for fine-tuning under changed settings: e.g. the
    get-up's smaller exploration noise, docs/getup.md)."""


@dataclasses.dataclass
class Hooks:
    """PPO hooks a task gives its training (``toolkit.rl.ppo.train``)."""

    on_iteration: Optional[Callable] = None
    extra: dict = dataclasses.field(default_factory=dict)
    should_stop: Optional[Callable[[], bool]] = None
    warm_start: Optional[Path] = None
    spec: Any = None
    """The env spec to train and roll out with, when the hooks change it (None: unchanged)."""
    state: dict = dataclasses.field(default_factory=dict)
    """The task's own bookkeeping (e.g. the curriculum), for ``final_env`` and ``measure``."""


TRAIN_SHARE = 0.9  #: the share of an evaluation's progress that training is; the rollouts and measures the rest


class PolicyTask(Task):
    """Train a policy, then measure its deterministic rollout (the shared wiring of policy tasks)."""

    env_path: ClassVar[str] = ""
    """``module:Class`` of the task's ``CharacterEnv`` (imported when first needed)."""
    cheap_evaluation: ClassVar[dict[str, str]] = {"filmstrip_frames": "0"}
    """``task.<key>`` values that make the part of an evaluation after training cheap (no
    filmstrip, fewer or shorter measuring episodes) without changing what training does: the
    training benchmark (``jt bench rollout --train``) runs with them."""

    def __init__(self, cfg: Any = None) -> None:
        if cfg is None:
            from toolkit.config import compose

            cfg = compose([f"task={self.Config().name}"])
        super().__init__(cfg)
        self.params = task_params(self.Config, cfg)

    # ------------------------------------------------------------------ what a task writes
    def env_spec(self, point: dict[str, float]) -> Any:
        """The picklable spec of the environment at ``point`` (missing names: the defaults)."""
        raise NotImplementedError

    def training(self, spec: Any, ctx: EvalContext) -> Hooks:
        """PPO hooks of one evaluation (default: none)."""
        return Hooks()

    def final_env(self, env: Any, hooks: Hooks, trained: tr.Trained) -> None:
        """Set up the environment of the deterministic rollout (e.g. the reached difficulty)."""

    def final_options(self, env: Any) -> Optional[dict]:
        """Reset options of the deterministic rollout."""
        return None

    def retry_rollout(self, env: Any, ro: Rollout) -> bool:
        """After a deterministic rollout ``ro``: True to roll out again, after changing ``env`` (e.g.
        an easier curriculum level). Default: never."""
        return False

    def record(self, env: Any) -> dict[str, Any]:
        """What the rollout logs per control step: time, root pose ``(7,)`` and CoM ``(3,)``."""
        q, _ = env.sim.state()
        return {"root": q[:7].copy(), "com": env.links_and_com()[1], "time": float(getattr(env, "t", env.sim.time))}

    def rollout_data(self, ro: Rollout, env: Any, spec: Any) -> tuple[dict, dict]:
        """``(datasets, attributes)`` of ``rollout.h5`` besides ``time``, ``root`` and ``com``; what
        ``measure`` needs from the env after the episode goes to ``ro.notes``."""
        return {}, {"return": float(ro.return_), "reason": str(ro.info.get("reason", ""))}

    def measure(self, spec: Any, ro: Rollout, trained: tr.Trained, hooks: Hooks, workdir: Path) -> Evaluation:
        """The evaluation's metrics from the deterministic rollout and the training."""
        from toolkit.policy.history import measured

        metrics, history = measured(ro, trained, {}, keep_nonfinite=True)
        return Evaluation(metrics=metrics, history=history)

    def sample_budget(self, ctx: EvalContext) -> int:
        """The evaluation's PPO budget: ``agent.total_samples`` of the ``agent`` group with the
        evaluation's seed (what the progress fractions of the training hooks divide by)."""
        return int(tr.agent_config(group_of(self.cfg, "agent"), ctx.seed).total_samples)

    # ------------------------------------------------------------------ jt play: a trained policy replayed
    def play_options(self, env: Any, start: Optional[str] = None) -> Optional[dict]:
        """Reset options of a replay (``jt play``): the final rollout's (``final_options``). ``start``
        is ``--start X``; a task whose episodes can start elsewhere (a phase, a time) reads it
        here, the others refuse it in one line."""
        if start is not None:
            from toolkit.errors import JtError

            raise JtError(f"--start={start}: task={type(self).name or self.Config().name} replays its one "
                          "start (its final rollout's); leave --start out")
        return self.final_options(env)

    def replay_attrs(self, env_attrs: dict[str, Any], metrics: dict[str, float]) -> dict[str, Any]:
        """Environment attributes a replay of a trained run sets (``jt play RUN``): the checkpoint's
        ``env_attrs`` (what training set last); ``metrics`` are the run's (empty when unknown), for
        a task whose final rollout set others."""
        return dict(env_attrs)

    def play_summary(self, env: Any, ro: Rollout) -> tuple[dict[str, Any], str]:
        """What a replay reached, ``(measure, line)``: the measure a shipped skill documents
        (plain numbers, bools, strings) and the line ``jt play`` prints. Default: the return,
        the control steps and the simulated seconds."""
        seconds = float(ro.time[-1] - ro.time[0]) if "time" in ro.series else ro.steps / float(env.control_hz)
        measure = {"return": round(float(ro.return_), 4), "steps": int(ro.steps), "seconds": round(seconds, 3)}
        return measure, f"return {ro.return_:.3f}, {ro.steps} control steps, {seconds:.2f} s"

    # ------------------------------------------------------------------ shared wiring
    @property
    def env_class(self) -> type:
        """The task's environment class (``env_path``)."""
        import importlib

        module, _, name = self.env_path.partition(":")
        return getattr(importlib.import_module(module), name)

    def character_groups(self) -> tuple[dict, dict]:
        """``({"sim": ..., "spd": ..., "character": ...}, action)`` as plain dicts (picklable)."""
        cfg = self.cfg
        sim = {k: plain(group_of(cfg, k)) for k in ("sim", "spd", "character")}
        return sim, plain(group_of(cfg, "action"))

    def make_env(self, point: Optional[dict[str, float]] = None, seed: Optional[int] = None) -> Any:
        """The task's environment at ``point`` (None: the defaults)."""
        return self.env_class(self.env_spec(dict(point or {})), seed=seed)

    def evaluate(self, point: dict[str, float], ctx: EvalContext) -> Evaluation:
        from toolkit.rl.checkpoint import load_policy
        from toolkit.store import h5

        p, workdir = self.params, Path(ctx.workdir)
        outer = ctx
        if ctx.progress is not None:  # training is the first TRAIN_SHARE of the evaluation's progress
            report = ctx.progress
            ctx = dataclasses.replace(ctx, progress=lambda f, m="": report(TRAIN_SHARE * f, m))
        spec = self.env_spec(point)
        hooks = self.training(spec, ctx)
        spec = hooks.spec if hooks.spec is not None else spec
        name = type(self).name or self.Config().name
        skill = trained_skill(self.cfg, name)
        attrs: dict[str, Any] = {}
        if skill is not None:  # task.evaluate=NAME: the skill's slim policy, in the environment it was trained in
            attrs = dict(skill.env_attrs)
            self.adopt_attrs(hooks, attrs)
            trained = tr.adopted(adopt_skill(skill, workdir), group_of(self.cfg, "agent"), ctx.seed)
        else:
            trained = tr.train_policy(tr.EnvFactory(self.env_class, spec), group_of(self.cfg, "agent"),
                                      group_of(self.cfg, "executor"), workdir, ctx.seed, hooks.on_iteration,
                                      hooks.extra, hooks.should_stop, hooks.warm_start or warm_policy(self.cfg, name),
                                      adopt_checkpoint(self.cfg, name, workdir))
        model = load_policy(trained.checkpoint)
        outer.report(TRAIN_SHARE, "final rollout")
        clock = [time.perf_counter()]
        with opened_env(self.env_class, spec, seed=ctx.seed) as env:
            self.final_env(env, hooks, trained)
            for key, value in attrs.items():  # as jt play sets them
                setattr(env, key, value)
            while True:
                ro = rollout(env, model, self.record, p.filmstrip_frames, p.filmstrip_width,
                             p.filmstrip_height, self.final_options(env))
                if not self.retry_rollout(env, ro):
                    break
            data, attrs = self.rollout_data(ro, env, spec)
            fps = float(env.control_hz)
        clock.append(time.perf_counter())
        written = tr.save_motion(workdir, ro.frames, p.filmstrip_frames, fps)
        h5.write(workdir / "rollout.h5", {"time": ro.time, "root": ro.root, "com": ro.com, **data}, attrs)
        clock.append(time.perf_counter())
        outer.report(TRAIN_SHARE + 0.02, "measuring the trained policy")
        ev = self.measure(spec, ro, trained, hooks, workdir)
        clock.append(time.perf_counter())
        ev.metrics.update(time_breakdown(trained, clock))
        outer.report(1.0, "done")
        if ev.artifacts is None:
            ev.artifacts = [n for n in (tr.CHECKPOINT, "rollout.h5", *written) if (workdir / n).exists()] + \
                self.extra_artifacts(workdir)
        return ev

    def adopt_attrs(self, hooks: Hooks, env_attrs: dict[str, Any]) -> None:
        """``task.evaluate=NAME``: bring the training hooks' state (a curriculum) to a shipped
        skill's environment attributes, as if training had ended there; nothing is trained.
        ``evaluate`` sets the attributes on the final rollout's environment after ``final_env``
        either way. Default: nothing."""

    def extra_artifacts(self, workdir: Path) -> list[str]:
        """Files of the task's own that the evaluation logs besides the shared ones."""
        return []
