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

import math

from pathlib import Path
from typing import Any, ClassVar, Optional

import numpy as np

from toolkit.config import group_of, plain
from toolkit.interfaces.searcher import Param, SearchProblem, Space
from toolkit.interfaces.task import EvalContext, Evaluation

from jt_tasks.getup.config import GetupConfig
from toolkit.policy.episodes import Rollout, opened_env, rollout
from toolkit.policy.history import IterationHistory, mean_of, measured, numbers
from toolkit.policy.task import Hooks, PolicyTask, require_character_and_prior

_FALLEN: dict[tuple, list] = {}  #: fallen_states memo per process: {(groups, params): states}
#: per-iteration means over episodes from the ground (clip first poses and rag-doll states; not
#: standing starts, nor clip starts inside the clip): ``early`` is the share ended by 003 §5.3's
#: early termination, ``success_clip`` / ``success_fallen`` the success of each start kind
HISTORY = ("success", "got_up", "r_task_mean", "task_return_rate", "early", "success_clip", "success_fallen")


class GetupTask(PolicyTask):
    """Get-up motions that track height and torso-angle curves (003): PPO, C-VAE actions, eqs 2-9."""

    key_metrics: ClassVar[tuple[str, ...]] = ("success_overall", "success_flat", "success_easy", "success_medium",
                                              "success_hard", "success_rate", "r_task_mean", "task_return_rate")
    Config: ClassVar[type] = GetupConfig
    env_path: ClassVar[str] = "jt_tasks.getup.env:GetupEnv"
    #: what GetupEnv.record_now gives the reward terms, what it gives an action space, what a curriculum may drive
    record_keys: ClassVar[frozenset[str]] = frozenset({
        "h", "theta_x", "theta_z", "target_h", "target_theta_x", "target_theta_z", "target_h_end",
        "link_ang_vel", "joint_rotations", "neutral_rotations", "naturalness"})
    #: the C-VAE's condition (003 §3.4); a feed-forward's phase on the episode's clip (action=ffc_fbc, ours)
    action_inputs: ClassVar[frozenset[str]] = frozenset({"condition", "phase"})
    curriculum_attrs: ClassVar[frozenset[str]] = frozenset({"terrain_level"})
    #: one deterministic episode, no periodic evaluation, no Table 1 evaluation (a benchmark's)
    cheap_evaluation: ClassVar[dict[str, str]] = {"filmstrip_frames": "0", "eval_episodes": "1",
                                                  "eval_every": str(10 ** 9), "eval_regions": "[]"}
    #: ``jt study getup TOOL``: the analysis tools (``jt_tasks.getup.analysis``)
    studies: ClassVar[dict[str, str]] = {"policy": "jt_tasks.getup.analysis.study:main"}

    @classmethod
    def check_run(cls, cfg: Any) -> None:
        """The humanoid (the curves and start poses come from its clips) and a prior for action=cvae/pvae."""
        require_character_and_prior(cfg, "getup", "humanoid", "its curves and start poses come from the DeepMimic "
                                               "humanoid's get-up clips")
        from toolkit.errors import JtError

        from jt_tasks.getup.terrain import REGIONS

        action = group_of(cfg, "action")
        if action is not None and str(action.get("name", "")) == "ffc_fbc":  # the feed-forward follows each curve's clip
            from jt_tasks.getup.curves import REFERENCE

            curves = list(group_of(cfg, "task").get("curves") or [])
            authored = [c for c in curves if c not in REFERENCE]
            if authored:
                raise JtError(f"task.curves={curves}: action=ffc_fbc puts each curve's clip pose under the policy, and "
                              f"{', '.join(authored)} has no clip; use the reference curves ({', '.join(REFERENCE)})")
        node = group_of(cfg, "curriculum")
        if node is not None and str(node.get("name", "")) == "terrain":
            regions = list(node.get("regions") or [])
            if regions != list(REGIONS[:len(regions)]):
                raise JtError(f"curriculum.regions={regions}: the get-up terrain's regions are {', '.join(REGIONS)}, "
                              "in this order (a prefix of them, e.g. [flat, easy])")

    def problem(self) -> SearchProblem:
        return SearchProblem(space=Space((Param("time_scale", 0.5, 2.0, float(self.params.time_scale)),)))

    def curve_set(self, time_scale: float) -> list:
        from jt_tasks.getup.curves import build_curves

        p = self.params
        return build_curves(list(p.curves), dict(p.authored), list(p.authored_durations) or None, p.n_control,
                            p.extraction, p.clamped, time_scale)

    def train_regions(self) -> list[int]:
        """Regions that get training rag-doll states: all of the terrain's with ``curriculum=terrain``
        (``train_regions: curriculum``), else flat only."""
        p = self.params
        node = group_of(self.cfg, "curriculum")
        terrain_cur = node is not None and str(node.get("name", "")) == "terrain"
        if not p.terrain or p.train_regions == "flat" or not terrain_cur:
            return [0]
        return list(range(len(p.terrain["roughness"])))

    def fallen(self, sim: dict, regions: Optional[list[int]] = None, n: Optional[int] = None,
               seed: Optional[int] = None) -> list:
        """Rag-doll states of ``regions`` (default: ``train_regions()``), ``n`` each (``n_fallen``),
        dropped with ``seed`` (``fallen_seed``); memoised per process and, during an evaluation,
        kept in its folder (``drops_<hash>.json``), so a resumed run does not drop them again."""
        import hashlib
        import json

        from jt_tasks.getup.initial import fallen_states

        p = self.params
        folder = getattr(self, "_drops_dir", None)
        n = p.n_fallen if n is None else int(n)
        seed = p.fallen_seed if seed is None else int(seed)
        out = []
        for region in (self.train_regions() if regions is None else regions):
            key = (repr(sim), repr(dict(p.terrain or {})), region, n, seed, tuple(p.fallen_styles), p.drop_height,
                   p.drop_perturb, p.ragdoll_kd, p.settle_max, p.rest_speed, p.drop_hz)
            cache = None if folder is None else \
                Path(folder) / f"drops_{hashlib.sha1(repr(key).encode()).hexdigest()[:16]}.json"
            if key not in _FALLEN and cache is not None and cache.exists():
                _FALLEN[key] = json.loads(cache.read_text())
            if key not in _FALLEN:
                _FALLEN[key] = fallen_states(sim, n, seed, tuple(p.fallen_styles), p.drop_height, p.drop_perturb,
                                             p.ragdoll_kd, p.settle_max, p.rest_speed,
                                             terrain=dict(p.terrain or {}) or None, region=region, sim_hz=p.drop_hz)
                if cache is not None:  # written whole, then renamed: a kill never leaves half a file
                    from toolkit.store.atomic import write_text

                    write_text(cache, json.dumps(_FALLEN[key]))
            out.extend(_FALLEN[key])
        return out

    def evaluate(self, point: dict[str, float], ctx: EvalContext) -> Evaluation:
        self._drops_dir = Path(ctx.workdir)  # the rag-doll drops are kept with the evaluation
        try:
            return super().evaluate(point, ctx)
        finally:
            self._drops_dir = None

    def env_spec(self, point: dict[str, float]) -> Any:
        from jt_tasks.getup.env import GetupSpec
        from toolkit.policy.spec import spec_of

        p = self.params
        sim, action = self.character_groups()
        if p.friction is not None:
            sim["sim"] = {**(sim.get("sim") or {}), "friction": float(p.friction)}
        scale = float(point.get("time_scale", p.time_scale))
        reward = plain(group_of(self.cfg, "reward")) or {}
        return spec_of(GetupSpec, p, curves=[c.to_dict() for c in self.curve_set(scale)], fallen=self.fallen(sim),
                       reward=dict(reward), terrain=plain(p.terrain) if p.terrain else {}, sim=sim, action=action)

    # ------------------------------------------------------------------ evaluation (PolicyTask hooks)
    def training(self, spec: Any, ctx: EvalContext) -> Hooks:
        """The curriculum, the per-iteration history (``extra["getup_history"]``) and, every
        ``eval_every`` iterations, deterministic get-ups from perturbed clip starts
        (``stage1.ClipStartTraining``, ``extra["eval_history"]``)."""
        import functools

        from jt_tasks.getup.stage1 import ClipStartTraining
        from toolkit import plugins

        total = self.sample_budget(ctx)
        node = group_of(self.cfg, "curriculum")
        cur = plugins.load("curriculum", str(node.name))(node) if node is not None and "name" in node else None
        extra: dict[str, Any] = cur.bind({}) if cur is not None else {}

        def row(eps: list, stats: Any) -> list[float]:  # ground starts only, then by start kind
            ground = [e for e in eps if e.get("start_kind", 0.0) != 2.0 and not e.get("start_time", 0.0)]
            kinds = [[e for e in ground if e.get("start_kind", 0.0) == k] for k in (0.0, 1.0)]
            return [mean_of(ground, k) for k in HISTORY[:5]] + [mean_of(eps_k, "success") for eps_k in kinds]

        hist = IterationHistory(extra, "getup_history", HISTORY, total, ctx.progress, row,
                                ("success", ".2f", "— (no episode from the ground ended yet)"),
                                cur.on_iteration if cur is not None else None)
        p = self.params
        window = None
        if p.rsi > 0.0 and (p.rsi_from > 0.0 or p.rsi_step > 0.0):  # the reverse curriculum (reverse.py)
            from jt_tasks.getup.reverse import StartWindow

            window = StartWindow(p.rsi_from, p.rsi_step, p.rsi_success, p.rsi_episodes, extra, hist.on_iteration)
        hook = ClipStartTraining(functools.partial(self.env_class, spec, seed=ctx.seed), p.eval_clip_during,
                                 p.eval_start_noise, p.eval_every, extra, window or hist.on_iteration, ctx.progress,
                                 total)
        return Hooks(on_iteration=hook, extra=extra, state={"cur": cur, "training": hook, "history": hist,
                                                            "window": window})

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

    def play_options(self, env: Any, start: Optional[str] = None) -> Optional[dict]:
        """``jt play --start``: a curve's clip start (``facedown``, ``faceup_mirror`` ...) or
        ``drop`` (the first rag-doll state); default the final rollout's (``task.eval_curve``)."""
        if start is None:
            return self.final_options(env)
        from toolkit.errors import JtError

        names = [c.name for c in env.curves if c.clip]
        if start == "drop":
            if not env.spec_.fallen:
                raise JtError("--start=drop: this configuration makes no rag-doll states (task.n_fallen=0)")
            return {"kind": "fallen", "fallen": 0}
        if start not in names:
            raise JtError(f"--start={start}: one of {', '.join(names)} (a clip's first pose) or drop (a rag-doll state)")
        return {"kind": "clip", "curve": start}

    def play_summary(self, env: Any, ro: Rollout) -> tuple[dict[str, Any], str]:
        """Got up (the standing height reached) and when, stood to the end (003 §6.3's rule as the
        env applies it) or why the episode ended; ``{"got_up", "stood", "time_to_rise_s", "peak_h_m"}``."""
        _, tail = super().play_summary(env, ro)
        info = ro.info
        got_up, stood = bool(info.get("got_up", 0.0)), bool(info.get("success", 0.0))
        rise = float(info.get("time_to_rise", math.nan))
        peak = max((row["h"] for row in env.log), default=math.nan)
        if stood:
            head = f"got up in {rise:.2f} s and stood to the end"
        elif got_up:
            head = f"got up in {rise:.2f} s, then fell ({info.get('reason', '')})"
        else:
            head = f"did not get up: neck at most {peak:.2f} m ({info.get('reason', '')})"
        measure = {"got_up": got_up, "stood": stood, "time_to_rise_s": round(rise, 3) if got_up else None,
                   "peak_h_m": round(float(peak), 3)}
        return measure, f"{head} ({tail})"

    def record(self, env: Any) -> dict[str, Any]:
        out = super().record(env)
        m = env.measure()
        out["features"] = np.asarray(m["features"], float)
        out["targets"] = np.asarray(env.targets(env.t), float)
        return out

    def rollout_data(self, ro: Rollout, env: Any, spec: Any) -> tuple[dict, dict]:
        info = ro.info
        ro.notes["log"] = list(env.log)
        data = {"features": ro.series["features"], "targets": ro.series["targets"],
                "curve_control": np.asarray(env.curve.control), "info": numbers(info)}
        if env.log:
            data["terms"] = {k: np.array([row[k] for row in env.log]) for k in env.log[0]}
        attrs = {"curve": env.curve.name, "duration": float(env.curve.duration), "start_kind": env.start_kind,
                 "return": float(ro.return_), "reason": str(info.get("reason", ""))}
        return data, attrs

    def measure(self, spec: Any, ro: Rollout, trained: Any, hooks: Hooks, workdir: Path) -> Evaluation:
        from toolkit.rl.checkpoint import load_policy

        from jt_tasks.getup import evaluate as E

        res, info, p = trained.result, ro.info, self.params
        infos = [info]
        model = load_policy(trained.checkpoint)
        if p.eval_episodes > 1:
            with opened_env(self.env_class, spec, seed=0) as env:
                for opts in self.eval_options(env, p.eval_episodes)[1:]:
                    infos.append(rollout(env, model, options=opts).info)
        metrics = {
            "success": float(info.get("success", 0.0)), "got_up": float(info.get("got_up", 0.0)),
            "success_rate": float(np.mean([i.get("success", 0.0) for i in infos])),
            "got_up_rate": float(np.mean([i.get("got_up", 0.0) for i in infos])),
            "r_task_mean": float(info.get("r_task_mean", 0.0)),
            "task_return_rate": float(np.mean([i.get("task_return_rate", 0.0) for i in infos])),
            "episode_time": float(info.get("episode_time", 0.0))}
        if p.eval_clip_starts > 0:  # issue 29's stage 1: perturbed clip starts, seeds never used in training
            from jt_tasks.getup.stage1 import clip_start_success

            with opened_env(self.env_class, spec, seed=0) as env:
                st1 = clip_start_success(env, model, p.eval_clip_starts, p.eval_start_noise, seed=0)
            metrics["success_clip"], metrics["got_up_clip"] = st1["success"], st1["got_up"]
        if p.eval_regions:  # 003 §6.3, Table 1
            table = E.evaluate_regions(self, spec, model)
            figures = E.table_metrics(table)
            metrics.update(figures)
            E.write_table(workdir / "table1.h5", table, figures)
        E.plot_curves(workdir / "curves.png", np.asarray(ro.time, float), np.asarray(ro.series["features"], float),
                      np.asarray(ro.series["targets"], float),
                      f"{info.get('reason', '')}: curve {spec.curves[int(info.get('curve', 0))]['name']}")
        for k in ("r_getup_height", "r_getup_torso", "r_getup_velocity", "r_getup_pose", "r_naturalness"):
            if f"{k}_mean" in info:
                metrics[f"{k}_mean"] = float(info[f"{k}_mean"])
        cur = hooks.state.get("cur")
        if cur is not None:
            if res.extra.get(cur.extra_key):
                cur.load_state(dict(res.extra[cur.extra_key]))
            level = cur.env_attrs().get("terrain_level")  # what the env reads (Curriculum.env_attrs)
            if level is not None:
                metrics["terrain_level"] = float(level)
        metrics, history = measured(ro, trained, metrics, hooks.state["history"].curves(res.extra, prefix="train_"))
        rows = hooks.state["training"].history() if "training" in hooks.state else np.zeros((0, 3))
        if len(rows):  # the deterministic get-ups from perturbed clip starts during training
            history.update(hooks.state["training"].curves({"success": "eval_success_clip",
                                                           "got_up": "eval_got_up_clip"}))
            metrics["best_success_clip_during"] = float(rows[:, 1].max())
        if hooks.state.get("window") is not None:  # the reverse curriculum's front over training
            from jt_tasks.getup.reverse import KEY, MOVES_KEY

            moves = np.asarray(res.extra.get(MOVES_KEY, np.zeros((0, 2))), float).reshape(-1, 2)
            history["rsi_from"] = [(0, float(self.params.rsi_from))] + [(int(s), float(f)) for s, f in moves]
            metrics["rsi_from_final"] = float(np.asarray(res.extra.get(KEY, [self.params.rsi_from]), float).reshape(-1)[0])
        return Evaluation(metrics=metrics, history=history)

    def extra_artifacts(self, workdir: Path) -> list[str]:
        """``table1.h5`` (003 Table 1, per episode) and ``curves.png`` (features achieved vs targeted)."""
        return [n for n in ("table1.h5", "curves.png") if (workdir / n).exists()]
