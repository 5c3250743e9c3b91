"""``task=highjump|obstacle|longjump``: one evaluation = train a jump policy from a take-off state.

Stage 1 of ``000`` (§5.1, §6.1): the searcher (``search=bds``) explores the take-off features;
each evaluation trains PPO (``cfg.agent``) with the action space (``cfg.action``, P-VAE by
default), the product reward (``cfg.reward``) and the curriculum (``cfg.curriculum``) until
``z_freeze`` or the sample budget, then measures the strategy feature of the deterministic policy:
the angle between the root's up axis and world up when the CoM crosses the bar plane (``000``
§6.1.4), range ``[0, pi]``. Stage 2 (``task.stage=2 task.init=...``): ``jt_tasks.jumping.stage2``.

Groups left null fall back to this task's choices (``task.action``, ``task.reward``,
``task.curriculum``, ``task.spd``), so ``jt run task=highjump`` works on the base config.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, ClassVar, Optional

import numpy as np

from toolkit.config import group_of, plain
from toolkit.interfaces.searcher import Param, SearchProblem, Space
from toolkit.interfaces.task import EvalContext, Evaluation

from jt_tasks.jumping.config import JumpConfig, LongJumpConfig, ObstacleConfig
from toolkit.policy.episodes import Rollout
from toolkit.policy.task import PolicyTask, require_character_and_prior


def require_own_control_rate(cfg: Any, task: str) -> None:
    """One ``JtError`` line when ``sim.control_hz`` is set for a jump: the bar-height curriculum
    sets the control rate (000 §6.1.2: 10 → 30 Hz, ``curriculum.control_hz_start`` / ``_span``)."""
    from toolkit import plugins
    from toolkit.errors import JtError

    sim = group_of(cfg, "sim")
    if sim is None or "control_hz" not in sim:
        return
    default = getattr(getattr(plugins.load("sim", str(sim.name)), "Config", None), "control_hz", None)
    if default is not None and float(sim.control_hz) != float(default):
        raise JtError(f"sim.control_hz={sim.control_hz}: task={task} takes its control rate from the curriculum "
                      f"(curriculum.control_hz_start, curriculum.control_hz_span; 000 §6.1.2), not from sim")


class JumpTask(PolicyTask):
    """Base of the jumping tasks: take-off features → trained policy → strategy feature (000 §6.1)."""

    key_metrics: ClassVar[tuple[str, ...]] = ("n_strategies", "n_with_feature", "strategy_angle",
                                              "bar_height_reached", "success_rate")
    """A search's strategy count and evaluations with a feature (``summarize``; what ``jt compare
    --vary search=bds,random`` tabulates), then each evaluation's own."""
    kind: ClassVar[str] = "highjump"
    feature_names: ClassVar[tuple[str, ...]] = ("alpha", "omega_x", "omega_z", "v_z")
    Config: ClassVar[type] = JumpConfig
    env_path: ClassVar[str] = "jt_tasks.jumping.env:JumpEnv"
    action_inputs: ClassVar[frozenset[str]] = frozenset()  #: neither a phase nor a C-VAE condition
    #: what JumpEnv.episode_record gives the reward terms
    record_keys: ClassVar[frozenset[str]] = frozenset({
        "success", "root_ang_vel_mean", "head_first_landing", "naturalness", "feature", "policy_features"})
    #: what a curriculum may drive: the jump's own difficulty, the control rate, the P-VAE's offset
    curriculum_attrs: ClassVar[frozenset[str]] = frozenset({"bar_height", "control_hz", "c_offset"})
    #: ``jt study highjump TOOL`` (and obstacle, longjump): the analysis tools (``jt_tasks.jumping.analysis``)
    studies: ClassVar[dict[str, str]] = {"curves": "jt_tasks.jumping.analysis.curves:main"}
    #: ``jt play NAME``: the jumps' shipped trained skills, a folder each (``fosbury``: 1.00 m)
    skills: ClassVar[str] = "jt_tasks.jumping.skills"

    @classmethod
    def check_run(cls, cfg: Any) -> None:
        """The jumps need the humanoid (their take-off states come from its clips) and, for the
        P-VAE / C-VAE action spaces, a trained prior; their control rate is the curriculum's, so a
        ``sim.control_hz`` other than the simulator's default is refused, not ignored."""
        require_character_and_prior(cfg, cls.Config().name, "humanoid", "its take-off states come from the DeepMimic humanoid's clips")
        require_own_control_rate(cfg, cls.Config().name)

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        cfg = self.cfg
        if self.params.stage == 2:
            from jt_tasks.jumping.stage2 import check_reward

            check_reward(plain(group_of(cfg, "reward")).get("terms", {}), self.params.name)
        self._stage2: Any = None
        self._takeoff_file: Optional[Path] = None

    # ------------------------------------------------------------------ Stage 2 (000 §5.2)
    def stage2_init(self) -> Any:
        """``jt_tasks.jumping.stage2.Stage2Init`` of ``task.init`` (resolved once); None in Stage 1."""
        from toolkit.errors import JtError

        p = self.params
        if p.stage not in (1, 2):
            raise JtError(f"task.stage={p.stage}: 1 (take-off exploration) or 2 (novel policy seeking)")
        if p.stage == 1:
            if str(p.init or "").strip():
                raise JtError("task.init is for Stage 2: add task.stage=2")
            return None
        if self._stage2 is None:
            from jt_tasks.jumping.stage2 import resolve

            store = group_of(self.cfg, "store")
            self._stage2 = resolve(p, str(store) if store is not None else None, str(p.name), self.feature_names)
        return self._stage2

    def takeoff_file(self) -> Optional[Path]:
        """The run-up's ``takeoff_state.h5`` of ``task.takeoff_from`` (resolved once); None if unset."""
        ref = str(self.params.takeoff_from or "").strip()
        if ref and self._takeoff_file is None:
            from jt_tasks.takeoff import source as takeoff_source

            store = group_of(self.cfg, "store")
            self._takeoff_file = takeoff_source.resolve(ref, str(store) if store is not None else None)
        return self._takeoff_file if ref else None

    def _fixed(self) -> dict:
        """Take-off features not searched: ``task.point``, a run-up's achieved ones
        (``task.takeoff_from``), or in Stage 2 the init's take-off state."""
        init = self.stage2_init()
        if init is not None:
            return dict(init.features)
        fixed = dict(self.params.point or {})
        if self.takeoff_file() is not None:
            from jt_tasks.takeoff import source as takeoff_source

            fixed.update(takeoff_source.features(self.takeoff_file(), self.feature_names))
        return fixed

    # ------------------------------------------------------------------ search problem
    def ranges(self) -> dict[str, tuple[float, float]]:
        """The search box ``{feature: (low, high)}`` (``task.ranges``)."""
        return {k: (float(v[0]), float(v[1])) for k, v in (self.params.ranges or {}).items()}

    def problem(self) -> SearchProblem:
        from jt_tasks.jumping.features import angle_distance

        r, d = self.ranges(), dict(self.params.takeoff or {})
        if self.params.stage == 2:
            search = group_of(self.cfg, "search")
            if search is not None and str(group_of(search, "name")) != "single":
                from toolkit.errors import JtError

                raise JtError("task.stage=2 trains one policy from task.init: use search=single (the default)")
        names = [n for n in self.feature_names if n not in self._fixed()]
        space = Space(tuple(Param(n, r[n][0], r[n][1], d.get(n)) for n in names))
        constraint = self.reach_constraint(names)
        return SearchProblem(space=space, n_features=1, feature_low=[0.0], feature_high=[math.pi],
                             feature_distance=angle_distance, distinct_threshold=self.params.distinct_threshold,
                             constraint=constraint,
                             constraint_name=f"task.max_time_to_bar={self.params.max_time_to_bar}" if constraint else "")

    def reach_constraint(self, names: list[str]) -> Any:
        """``task.max_time_to_bar`` as a known constraint of the box (``BarReach``), or None.

        None unless the task is a high jump, the time is set and alpha or v_z is searched (the
        others do not change the speed towards the bar)."""
        t_max = self.params.max_time_to_bar
        if self.kind != "highjump" or t_max is None or not {"alpha", "v_z"} & set(names):
            return None
        from jt_tasks.jumping.reach import BarReach

        return BarReach.of_task(self, names, float(t_max))

    # ------------------------------------------------------------------ building blocks
    def env_spec(self, point: dict[str, float]) -> Any:
        """The ``EnvSpec`` for take-off features ``point`` (missing ones: the defaults)."""
        from jt_tasks.jumping.env import EnvSpec
        from jt_tasks.jumping.scene import SuiteSpec
        from toolkit.policy.spec import spec_of

        p, cfg = self.params, self.cfg
        feats = {**(p.takeoff or {}), **{k: float(v) for k, v in point.items()},
                 **{k: float(v) for k, v in self._fixed().items()}}
        feats = {k: float(feats[k]) for k in self.feature_names}
        suite = SuiteSpec(kind=self.kind, alpha=feats.get("alpha", 0.0), distance=p.distance,
                          obstacle_height=p.obstacle_height, mat_height=p.mat_height)
        sim, action = self.character_groups()
        terms = plain(group_of(cfg, "reward")).get("terms", {})
        init = self.stage2_init()
        pol = init.policy_features if init is not None else (p.policy_features or [])
        return spec_of(EnvSpec, p, kind=self.kind, features=feats, suite=suite,
                       omega_y=p.omega_y if self.kind == "highjump" else None,
                       takeoff_file=str(self.takeoff_file() or ""), sim=sim, action=action, reward_terms=terms,
                       policy_features=[list(map(float, f)) for f in pol])

    def curriculum(self) -> Any:
        """The curriculum plugin of the ``curriculum`` group (the task's YAML chooses one)."""
        from toolkit import plugins
        from toolkit.errors import JtError

        node = group_of(self.cfg, "curriculum")
        if node is None:
            raise JtError(f"task={self.params.name} needs a curriculum: curriculum=<{', '.join(plugins.names('curriculum'))}>")
        return plugins.load("curriculum", str(node.name))(node)

    # ------------------------------------------------------------------ evaluation (PolicyTask hooks)
    def training(self, spec: Any, ctx: EvalContext) -> Any:
        from jt_tasks.jumping.train import curriculum_hooks

        init = self.stage2_init()
        total = self.sample_budget(ctx)
        return curriculum_hooks(spec, self.curriculum(), total, ctx.progress,
                                warm_start=init.checkpoint if init is not None else None)

    def final_env(self, env: Any, hooks: Any, trained: Any) -> None:
        from jt_tasks.jumping.train import after_training

        after_training(hooks, trained.result)
        cur = hooks.state["cur"]
        for k, v in cur.env_attrs().items():  # the reached difficulty
            setattr(env, k, v)
        p = getattr(cur, "params", None)  # z_min / dz of a bar_height-like curriculum; others: no fallback
        z_min, dz = getattr(p, "z_min", None), getattr(p, "dz", None)
        self._fallback = (float(z_min), float(dz), hooks.state["z_attr"]) if z_min is not None and dz else None

    def adopt_attrs(self, hooks: Any, env_attrs: dict[str, Any]) -> None:
        """A shipped skill's bar (``task.evaluate=NAME``): the curriculum at the level of that bar,
        so ``final_env`` sets it (and its control rate and offset) and ``bar_height_trained`` is
        it; a bar off the curriculum's grid, or a curriculum without levels, is left as it is
        (``evaluate`` sets the skill's attributes on the environment either way)."""
        cur, attr = hooks.state["cur"], hooks.state["z_attr"]
        p, z = getattr(cur, "params", None), env_attrs.get(attr)
        z_min, dz = getattr(p, "z_min", None), getattr(p, "dz", None)
        if z is None or z_min is None or not dz or not hasattr(cur, "level"):
            return
        level = round((float(z) - float(z_min)) / float(dz))
        try:
            cur.load_state({"level": level, "accumulator": 0.0})
        except (ValueError, KeyError):
            return
        if abs(float(cur.env_attrs().get(attr, math.nan)) - float(z)) > 1e-9:
            cur.load_state({"level": 0, "accumulator": 0.0})

    def retry_rollout(self, env: Any, ro: Rollout) -> bool:
        """``task.final_fallback``: one Δz lower when the jump never crossed the plane (not below z_min)."""
        fallback = getattr(self, "_fallback", None)
        if not self.params.final_fallback or fallback is None or math.isfinite(env.tracker.stage1()):
            return False
        z_min, dz, attr = fallback
        z = round(float(env.difficulty) - dz, 9)
        if z < z_min - 1e-9:
            return False
        setattr(env, attr, z)
        return True

    def rollout_data(self, ro: Rollout, env: Any, spec: Any) -> tuple[dict, dict]:
        notes = ro.notes
        notes["feature_quat"] = env.tracker.stage2(env.suite.rotation())
        notes["feature_angle"] = env.tracker.stage1()
        notes["feature_time"] = float(env.tracker.time)
        notes["final_z"] = float(env.difficulty)
        data = {"feature_quat": np.asarray(notes["feature_quat"], dtype=float),
                "feature_angle": np.array([notes["feature_angle"]])}
        attrs = {"features": {k: float(v) for k, v in spec.features.items()}, "kind": spec.kind,
                 "return": float(ro.return_), "reason": str(ro.info.get("reason", ""))}
        return data, attrs

    def measure(self, spec: Any, ro: Rollout, trained: Any, hooks: Any, workdir: Path) -> Evaluation:
        from jt_tasks.jumping.train import jump_curves
        from toolkit.policy.history import finite, measured

        res, init, notes = trained.result, self.stage2_init(), ro.notes
        trained_z = float(hooks.state["cur"].env_attrs().get(hooks.state["z_attr"], math.nan))  # the curriculum's z
        succ = [r for _, _, r in hooks.state["z_hist"] if math.isfinite(r)]
        angle = float(notes["feature_angle"])
        own = {"strategy_angle": angle, "bar_height_reached": float(notes.get("final_z", trained_z)),
               "bar_height_trained": trained_z,
               "success_rate": succ[-1] if succ else 0.0 if hooks.state["z_hist"] else math.nan,  # nan: no training
               "final_success": float(ro.info.get("success", 0.0))}
        own.update({f"takeoff_{k}": float(v) for k, v in spec.features.items()})
        own.update({f"feature_q{i}": float(v) for i, v in enumerate(notes["feature_quat"])})
        if init is not None:
            from jt_tasks.jumping.stage2 import novelty_metrics

            own.update(novelty_metrics(notes["feature_quat"], spec.policy_features, spec.reward_terms))
            own["init_eval_index"] = float(init.eval_index)
        metrics, history = measured(ro, trained, own, jump_curves(hooks, res), keep_nonfinite=True)
        self._write_peak(ro, workdir)
        if not math.isfinite(angle):
            return Evaluation(metrics=finite(metrics), failed=True,
                              reason="the deterministic jump never crossed the bar plane", history=history)
        return Evaluation(metrics=metrics, features=[angle], history=history)

    def _write_peak(self, ro: Rollout, workdir: Path) -> None:
        """``peak.png``: the rendered control step nearest the CoM's crossing of the bar plane
        (the strategy gallery's picture, ``000`` Fig. 7); nothing when it never crossed."""
        from jt_tasks.jumping.gallery import PEAK

        t, frames = float(ro.notes.get("feature_time", math.nan)), ro.frames
        if not math.isfinite(t) or not frames:
            return
        import imageio.v3 as iio

        i = int(np.argmin(np.abs(np.asarray(ro.time, dtype=float)[: len(frames)] - t)))
        iio.imwrite(Path(workdir) / PEAK, np.asarray(frames[i])[..., :3].astype(np.uint8))

    def extra_artifacts(self, workdir: Path) -> list[str]:
        """``peak.png`` when the jump crossed the bar plane."""
        from jt_tasks.jumping.gallery import PEAK

        return [PEAK] if (Path(workdir) / PEAK).is_file() else []

    # ------------------------------------------------------------------ jt play
    def _z_names(self) -> tuple[str, str, str]:
        """The curriculum's attribute, what it measures, and its measure's key."""
        if self.kind == "highjump":
            return "bar_height", "the bar at {z:.2f} m", "bar_m"
        return "obstacle_width", "the obstacle {z:.2f} m wide", "obstacle_width_m"

    def replay_attrs(self, env_attrs: dict[str, Any], metrics: dict[str, float]) -> dict[str, Any]:
        """The checkpoint's attributes, with the bar (width) the final rollout reached when the run
        recorded it: ``task.final_fallback`` may have jumped one Δz below the curriculum's last."""
        out = dict(env_attrs)
        attr = self._z_names()[0]
        z = metrics.get("bar_height_reached")
        if z is not None and math.isfinite(float(z)) and attr in out:
            out[attr] = float(z)
        return out

    def play_summary(self, env: Any, ro: Rollout) -> tuple[dict[str, Any], str]:
        """Cleared or not, at which bar (width), and the strategy feature angle (rad) at the
        crossing; ``{"cleared", "bar_m" | "obstacle_width_m", "strategy_angle_rad"}``."""
        _, tail = super().play_summary(env, ro)
        _, what, key = self._z_names()
        z, angle = float(env.difficulty), float(env.tracker.stage1())
        cleared = bool(ro.info.get("success", 0.0))
        head = f"cleared {what.format(z=z)}" if cleared else \
            f"did not clear {what.format(z=z)} ({ro.info.get('reason') or 'the episode had not ended'})"
        feature = f"strategy feature angle {angle:.3f} rad" if math.isfinite(angle) else \
            "no strategy feature (never crossed the plane)"
        measure = {"cleared": cleared, key: round(z, 4),
                   "strategy_angle_rad": round(angle, 3) if math.isfinite(angle) else None}
        return measure, f"{head}; {feature} ({tail})"

    # ------------------------------------------------------------------ the search's summary
    def strategies(self, items: list[dict]) -> list[dict]:
        """The distinct strategies among ``items`` (``jt_tasks.jumping.gallery.strategies``)."""
        from jt_tasks.jumping.features import angle_distance
        from jt_tasks.jumping.gallery import strategies

        return strategies(items, float(self.params.distinct_threshold), angle_distance)

    def _items(self, evaluations: Any, folder: Optional[Path] = None) -> list[dict]:
        """``gallery.strategies``' input: one dict per evaluation (its files in ``folder.parent``)."""
        return [{"index": i, "features": list(ev.features), "metrics": dict(ev.metrics), "point": dict(ev.point),
                 "run_id": ev.run_id, "workdir": str(Path(folder).parent / f"eval_{i:04d}") if folder else ""}
                for i, ev in enumerate(evaluations)]

    def summarize(self, evaluations: Any, workdir: Path) -> dict[str, Any]:
        """The search's strategy count (``000`` §7.1.1: 6 distinct strategies in the first ten
        samples) and how many evaluations gave a feature at all."""
        items = self._items(evaluations)
        with_feature = sum(1 for it in items if it["features"] and math.isfinite(float(it["features"][0])))
        return {"n_strategies": float(len(self.strategies(items))), "n_with_feature": float(with_feature)}

    def summary_artifacts(self, evaluations: Any, folder: Path) -> list[Path]:
        """The strategy gallery (``000`` Fig. 7): per strategy its pose over the bar, labelled, and
        its GIF; ``gallery.png`` with all of them; ``strategies.json``."""
        from jt_tasks.jumping import gallery

        found = self.strategies(self._items(evaluations, folder))
        return gallery.write(found, Path(folder) / "gallery") if found else []

    def summary_table(self, evaluations: Any) -> Optional[tuple[list[str], list[list]]]:
        """One row per distinct strategy (``jt show RUN_ID`` prints it)."""
        from jt_tasks.jumping import gallery

        found = self.strategies(self._items(evaluations))
        return gallery.table(found) if found else None


class HighJumpTask(JumpTask):
    """High jump (000 §6.1): explore (alpha, omega_x, omega_z, v_z) at take-off, feature = root up-angle at the bar."""

    kind = "highjump"
    feature_names = ("alpha", "omega_x", "omega_z", "v_z")


class ObstacleTask(JumpTask):
    """Obstacle jump (000 §6.1): explore the take-off root angular velocity, feature = up-angle at the centre plane."""

    kind = "obstacle"
    feature_names = ("omega_x", "omega_y", "omega_z")
    Config = ObstacleConfig
    curriculum_attrs = frozenset({"obstacle_width", "control_hz", "c_offset"})  # the box's width, not a bar


class LongJumpTask(ObstacleTask):
    """Long jump: an obstacle jump with an obstacle of height 0 (clear the width, land on the mat)."""

    Config = LongJumpConfig
