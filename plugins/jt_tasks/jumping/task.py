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

import dataclasses
import math
from pathlib import Path
from typing import Any, ClassVar, Optional

from toolkit.config import group_of, plain
from toolkit.interfaces.plugin import Plugin
from toolkit.interfaces.searcher import Param, SearchProblem, Space
from toolkit.interfaces.task import EvalContext, Evaluation, Task

FOSBURY = {"alpha": -0.05, "omega_x": -3.0, "omega_z": 1.0, "v_z": -2.40}  # 000 Table 3


def reward_terms_from_conf(name: str) -> dict:
    """``terms`` of ``conf/reward/<name>.yaml`` (when the run config has no reward group)."""
    from omegaconf import OmegaConf

    from toolkit.config import conf_dir

    return OmegaConf.to_container(OmegaConf.load(Path(conf_dir()) / "reward" / f"{name}.yaml"))["terms"]


@dataclasses.dataclass
class JumpConfig:
    """Parameters shared by the jumping tasks (the ``task`` group)."""

    name: str = "highjump"
    stage: int = 1  # 1: take-off exploration (000 §5.1); 2: novel policy seeking (000 §5.2)
    init: str = ""  # Stage 2: Stage-1 run id (outer run or nested evaluation), or its folder / ppo.h5
    init_eval: int = -1  # Stage 2, outer init run: evaluation index to start from (-1: the best one)
    policy_features: list = dataclasses.field(default_factory=list)  # Stage 2: f_i (x,y,z,w) of earlier policies
    point: dict = dataclasses.field(default_factory=dict)  # fixed take-off features overriding the searched ones
    ranges: dict = dataclasses.field(default_factory=dict)  # {feature: [low, high]} (see the task YAML)
    takeoff: dict = dataclasses.field(default_factory=dict)  # {feature: default value} (the searched point's defaults)
    takeoff_from: str = ""  # task=runup run id / folder / takeoff_state.h5 to start from (000 §6.1.1); "": the clip frame
    distance: float = 0.9  # m, take-off point to the bar plane / obstacle (ours)
    obstacle_height: float = 0.5  # m (000 §6.1); 0 for the long jump
    mat_height: float = 0.3  # m, rigid landing block (ours)
    clip: str = "run"  # reference run clip (000 §6.1.1)
    foot: str = "right"  # take-off foot (ours: the outer foot of a Fosbury with the bar on the left)
    omega_y: Optional[float] = 3.0  # rad/s, fixed facing-frame omega_y of the high jump (000 §6.1.1)
    v_y: Optional[float] = 2.06  # m/s vertical root speed at take-off, the "jumping intention" of 000 §8
    # (ours: humanoid3d_jump.txt's lift-off speed, takeoff.liftoff_vertical_speed); None: the run clip's
    time_limit: float = 2.0  # s (000 §6.1)
    safe_margin: float = 0.2  # m (000 §6.1)
    check_every: int = 1  # substeps between contact checks (1 = every 600 Hz substep)
    action: str = "pvae"  # action space when cfg.action is null (000 §4.2)
    reward: str = "highjump"  # conf/reward/<this>.yaml when cfg.reward is null (000 eqs 2, 16)
    curriculum: str = "bar_height"  # curriculum when cfg.curriculum is null (000 §6.1.3)
    spd: str = "df"  # SPD backend when cfg.spd is null (ours: dense SPD, fastest for 34 DoF)
    distinct_threshold: float = 0.5  # rad: Stage-1 features closer than this are one strategy (ours)
    filmstrip_frames: int = 8  # frames of the final jump
    filmstrip_width: int = 160  # px per frame
    filmstrip_height: int = 120  # px


class JumpTask(Task):
    """Base of the jumping tasks: take-off features → trained policy → strategy feature (000 §6.1)."""

    key_metrics: ClassVar[tuple[str, ...]] = ("strategy_angle", "bar_height_reached", "success_rate")
    kind: ClassVar[str] = "highjump"
    feature_names: ClassVar[tuple[str, ...]] = ("alpha", "omega_x", "omega_z", "v_z")
    Config: ClassVar[type] = JumpConfig
    RANGES: ClassVar[dict] = {}
    DEFAULTS: ClassVar[dict] = {}

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        group = group_of(cfg, "task")
        params = Plugin.params_of(group) if group is not None else {}
        self.params = self.Config(**params)
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
        r = dict(self.RANGES)
        r.update({k: (float(v[0]), float(v[1])) for k, v in (self.params.ranges or {}).items()})
        return r

    def problem(self) -> SearchProblem:
        from jt_tasks.jumping.features import angle_distance

        r, d = self.ranges(), {**self.DEFAULTS, **(self.params.takeoff or {})}
        if self.params.stage == 2:
            search = group_of(self.cfg, "search")
            if search is not None and str(group_of(search, "name")) != "single":
                from toolkit.errors import JtError

                raise JtError("task.stage=2 trains one policy from task.init: use search=single (the default)")
        names = [n for n in self.feature_names if n not in self._fixed()]
        space = Space(tuple(Param(n, r[n][0], r[n][1], d.get(n)) for n in names))
        return SearchProblem(space=space, n_features=1, feature_low=[0.0], feature_high=[math.pi],
                             feature_distance=angle_distance, distinct_threshold=self.params.distinct_threshold)

    # ------------------------------------------------------------------ building blocks
    def env_spec(self, point: dict[str, float]) -> Any:
        """The ``EnvSpec`` for take-off features ``point`` (missing ones: the defaults)."""
        from jt_tasks.jumping.env import EnvSpec
        from jt_tasks.jumping.scene import SuiteSpec

        p, cfg = self.params, self.cfg
        feats = {**self.DEFAULTS, **(p.takeoff or {}), **{k: float(v) for k, v in point.items()},
                 **{k: float(v) for k, v in self._fixed().items()}}
        feats = {k: float(feats[k]) for k in self.feature_names}
        suite = SuiteSpec(kind=self.kind, alpha=feats.get("alpha", 0.0), distance=p.distance,
                          obstacle_height=p.obstacle_height, mat_height=p.mat_height)
        sim = {"sim": plain(group_of(cfg, "sim")), "spd": plain(group_of(cfg, "spd")) or {"name": p.spd},
               "character": plain(group_of(cfg, "character")) or {"name": "humanoid"}}
        action = plain(group_of(cfg, "action")) or {"name": p.action}
        reward = group_of(cfg, "reward")
        terms = plain(reward)["terms"] if reward is not None else reward_terms_from_conf(self.reward_name())
        init = self.stage2_init()
        pol = init.policy_features if init is not None else (p.policy_features or [])
        return EnvSpec(kind=self.kind, features=feats, suite=suite, clip=p.clip, foot=p.foot,
                       omega_y=p.omega_y if self.kind == "highjump" else None, v_y=p.v_y,
                       takeoff_file=str(self.takeoff_file() or ""),
                       time_limit=p.time_limit, safe_margin=p.safe_margin, check_every=p.check_every,
                       sim=sim, action=action, reward_terms=terms,
                       policy_features=[list(map(float, f)) for f in pol])

    def make_env(self, point: Optional[dict[str, float]] = None, seed: Optional[int] = None) -> Any:
        """The ``JumpEnv`` of take-off features ``point`` (missing: the defaults), bar at ``z_min``."""
        from jt_tasks.jumping.env import JumpEnv

        return JumpEnv(self.env_spec(dict(point or {})), seed=seed)

    def reward_name(self) -> str:
        return self.params.reward + ("_stage2" if self.params.stage == 2 else "")

    def curriculum(self) -> Any:
        from toolkit import plugins

        node = group_of(self.cfg, "curriculum")
        name = str(node.name) if node is not None else self.params.curriculum
        return plugins.load("curriculum", name)(node)

    # ------------------------------------------------------------------ evaluation
    def evaluate(self, point: dict[str, float], ctx: EvalContext) -> Evaluation:
        from jt_tasks.jumping.train import run_evaluation

        p = self.params
        spec = self.env_spec(point)
        init = self.stage2_init()
        if init is not None:
            from jt_tasks.jumping.stage2 import check_reward

            check_reward(spec.reward_terms)
        out = run_evaluation(spec, self.curriculum(), group_of(self.cfg, "agent"), Path(ctx.workdir),
                             ctx.seed, group_of(self.cfg, "executor"), p.filmstrip_frames,
                             (p.filmstrip_width, p.filmstrip_height), ctx.progress,
                             warm_start=init.checkpoint if init is not None else None)
        ro, res = out["rollout"], out["result"]
        angle = float(ro["feature_angle"])
        metrics = {
            "strategy_angle": angle, "bar_height_reached": float(out["z"]),
            "mean_return": float(ro["return"]),
            "train_mean_return": _last(res.history.get("mean_return", [])),
            "success_rate": out["succ"][-1] if out["succ"] else 0.0,
            "final_success": float(ro["info"].get("success", 0.0)),
            "samples": float(res.samples), "iterations": float(res.iterations),
            "samples_per_s": out["samples_per_s"], "train_wall_s": float(out["wall_s"]),
        }
        metrics.update({f"takeoff_{k}": float(v) for k, v in spec.features.items()})
        metrics.update({f"feature_q{i}": float(v) for i, v in enumerate(ro["feature_quat"])})
        if init is not None:
            from jt_tasks.jumping.stage2 import novelty_metrics

            metrics.update(novelty_metrics(ro["feature_quat"], spec.policy_features, spec.reward_terms))
            metrics["init_eval_index"] = float(init.eval_index)
        arts = ["ppo.h5", "rollout.h5"] + (["filmstrip.png"] if (Path(ctx.workdir) / "filmstrip.png").exists() else [])
        if not math.isfinite(angle):
            return Evaluation(metrics={k: v for k, v in metrics.items() if math.isfinite(v)}, failed=True,
                              reason="the deterministic jump never crossed the bar plane",
                              history=out["history"], artifacts=arts)
        return Evaluation(metrics=metrics, features=[angle], history=out["history"], artifacts=arts)


def _last(values: list) -> float:
    finite = [float(v) for v in values if math.isfinite(float(v))]
    return finite[-1] if finite else 0.0


class HighJumpTask(JumpTask):
    """High jump (000 §6.1): explore (alpha, omega_x, omega_z, v_z) at take-off, feature = root up-angle at the bar."""

    kind = "highjump"
    feature_names = ("alpha", "omega_x", "omega_z", "v_z")
    RANGES = {"alpha": (-0.5, 2.5), "omega_x": (-3.0, 3.0), "omega_z": (-3.0, 3.0), "v_z": (-2.5, -0.5)}
    DEFAULTS = dict(FOSBURY)


@dataclasses.dataclass
class ObstacleConfig(JumpConfig):
    """The obstacle jump's group (000 §6.1): the obstacle_width curriculum and reward."""

    name: str = "obstacle"
    reward: str = "obstacle"  # conf/reward/obstacle.yaml (000 §6.1.2)
    curriculum: str = "obstacle_width"  # (000 §6.1.3, Table 1)


class ObstacleTask(JumpTask):
    """Obstacle jump (000 §6.1): explore the take-off root angular velocity, feature = up-angle at the centre plane."""

    kind = "obstacle"
    feature_names = ("omega_x", "omega_y", "omega_z")
    Config = ObstacleConfig
    RANGES = {"omega_x": (-3.0, 3.0), "omega_y": (-3.0, 3.0), "omega_z": (-3.0, 4.0)}
    DEFAULTS = {"omega_x": 0.0, "omega_y": 0.0, "omega_z": 1.0}  # 000 Table 4, Straddle


@dataclasses.dataclass
class LongJumpConfig(ObstacleConfig):
    """The long jump's group: an obstacle jump over an obstacle of height 0 (a gap before the mat)."""

    name: str = "longjump"
    obstacle_height: float = 0.0  # no box: jump the width onto the mat (jt variation)


class LongJumpTask(ObstacleTask):
    """Long jump: an obstacle jump with an obstacle of height 0 (clear the width, land on the mat)."""

    Config = LongJumpConfig
