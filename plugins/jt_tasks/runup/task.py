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

import dataclasses
import math
from pathlib import Path
from typing import Any, ClassVar, Optional

from toolkit.config import group_of, plain, task_params
from toolkit.interfaces.searcher import Param, SearchProblem, Space
from toolkit.interfaces.task import EvalContext, Evaluation, Task


def jump_task_box(kind: str) -> tuple[dict[str, tuple[float, float]], dict[str, float]]:
    """``(ranges, defaults)`` of the take-off features of ``conf/task/<kind>.yaml`` (the jump task's
    search box: ``000`` Tables 3 / 4), falling back to the jump task classes' constants."""
    from jt_tasks.jumping.task import HighJumpTask, ObstacleTask

    cls = HighJumpTask if kind == "highjump" else ObstacleTask
    ranges, defaults = dict(cls.RANGES), dict(cls.DEFAULTS)
    try:
        from omegaconf import OmegaConf

        from toolkit.config import conf_dir

        node = OmegaConf.to_container(OmegaConf.load(Path(conf_dir()) / "task" / f"{kind}.yaml"), resolve=True)
        ranges.update({k: (float(v[0]), float(v[1])) for k, v in (node.get("ranges") or {}).items()})
        defaults.update({k: float(v) for k, v in (node.get("takeoff") or {}).items()})
    except Exception:  # noqa: BLE001 - no conf/ (an unusual install): the classes' values
        pass
    return ranges, defaults


@dataclasses.dataclass
class RunupConfig:
    """The ``task`` group of ``task=runup`` (conf/task/runup.yaml has each value's source)."""

    name: str = "runup"
    kind: str = "highjump"  # highjump (000 eq 13) | obstacle (000 eq 14)
    point: dict = dataclasses.field(default_factory=dict)  # target features fixed here are not searched
    ranges: dict = dataclasses.field(default_factory=dict)  # {feature: [low, high]}; unset: conf/task/<kind>.yaml
    target: dict = dataclasses.field(default_factory=dict)  # default targets; unset: conf/task/<kind>.yaml takeoff
    omega_y: Optional[float] = 3.0  # rad/s, the high jump's fixed omega_y target (000 §6.1.1)
    clip: str = "run"  # reference run (DeepMimic humanoid3d_run.txt; 000 used its own sprints)
    foot: str = "right"  # take-off foot (as the jump tasks)
    n_strides: int = 2  # take-off-foot mid-supports from the start to the take-off (ours)
    contact_tol: float = 0.06  # m: support-phase detection (jumping/takeoff.py)
    foot_clearance: float = 0.002  # m: take-off foot above the ground at take-off (jumping/env.py)
    control_hz: float = 30.0  # policy rate (Peng et al. 2018)
    check_every: int = 1  # substeps between early-termination contact checks
    w_imitation: float = 0.7  # w_I (ours; 000 gives no weights)
    w_goal: float = 0.3  # w_G (ours)
    goal_steps: Optional[float] = None  # terminal multiplier of w_G r_G; null: the episode's control steps
    eval_lead: Optional[float] = None  # s before a take-off mid-support the final rollout starts; None: n_strides cycles
    action: str = "raw"  # action space when cfg.action is null (DeepMimic: PD targets)
    spd: str = "df"  # SPD backend when cfg.spd is null
    filmstrip_frames: int = 8  # frames of the final run-up
    filmstrip_width: int = 160  # px per frame
    filmstrip_height: int = 120  # px


class RunupTask(Task):
    """DeepMimic run-up to a target take-off state (000 §6.1.1): imitation + take-off reward (eqs 13-14)."""

    key_metrics: ClassVar[tuple[str, ...]] = ("goal_reward", "imitation_reward", "mean_return")
    Config: ClassVar[type] = RunupConfig

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        self.params = task_params(self.Config, cfg)
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
        from jt_tasks.runup.env import RunupSpec

        p, cfg = self.params, self.cfg
        _, defaults = self.box()
        feats = {**defaults, **{k: float(v) for k, v in point.items()},
                 **{k: float(v) for k, v in (p.point or {}).items()}}
        sim = {"sim": plain(group_of(cfg, "sim")), "spd": plain(group_of(cfg, "spd")) or {"name": p.spd},
               "character": plain(group_of(cfg, "character")) or {"name": "humanoid"}}
        action = plain(group_of(cfg, "action")) or {"name": p.action}
        return RunupSpec(kind=p.kind, target={k: float(feats[k]) for k in self.feature_names},
                         omega_y=p.omega_y, clip=p.clip, foot=p.foot, n_strides=p.n_strides,
                         contact_tol=p.contact_tol, foot_clearance=p.foot_clearance, control_hz=p.control_hz,
                         check_every=p.check_every, w_imitation=p.w_imitation, w_goal=p.w_goal,
                         goal_steps=p.goal_steps, sim=sim, action=action)

    def make_env(self, point: Optional[dict[str, float]] = None, seed: Optional[int] = None) -> Any:
        """The ``RunupEnv`` with target features ``point`` (missing: the defaults)."""
        from jt_tasks.runup.env import RunupEnv

        return RunupEnv(self.env_spec(dict(point or {})), seed=seed)

    def evaluate(self, point: dict[str, float], ctx: EvalContext) -> Evaluation:
        from jt_tasks.takeoff.state_file import NAME
        from jt_tasks.runup.train import run_evaluation

        p = self.params
        spec = self.env_spec(point)
        out = run_evaluation(spec, group_of(self.cfg, "agent"), Path(ctx.workdir), ctx.seed, group_of(self.cfg, "executor"),
                             p.eval_lead, p.filmstrip_frames, (p.filmstrip_width, p.filmstrip_height), ctx.progress)
        ro, res = out["rollout"], out["result"]
        info = ro["info"]
        metrics = {
            "goal_reward": float(info.get("r_goal", 0.0)),
            "imitation_reward": float(info.get("r_imitation_mean", 0.0)),
            "mean_return": float(ro["return"]),
            "train_mean_return": _last(res.history.get("mean_return", [])),
            "took_off": float(info.get("took_off", 0.0)),
            "episode_time": float(info.get("episode_time", 0.0)),
            "samples": float(res.samples), "iterations": float(res.iterations),
            "samples_per_s": out["samples_per_s"], "train_wall_s": float(out["wall_s"]),
        }
        for k in ("pose", "vel", "ee", "com"):
            metrics[f"imitation_{k}"] = float(info.get(f"r_{k}_mean", 0.0))
        metrics.update({k: float(v) for k, v in info.items() if k.startswith(("takeoff_", "target_"))})
        metrics = {k: v for k, v in metrics.items() if math.isfinite(v)}
        arts = [n for n in ("ppo.h5", "rollout.h5", "filmstrip.png", NAME) if (Path(ctx.workdir) / n).exists()]
        if not info.get("took_off"):
            return Evaluation(metrics=metrics, failed=True, history=out["history"], artifacts=arts,
                              reason=f"the deterministic run-up ended before the take-off: {info.get('reason', '')}")
        return Evaluation(metrics=metrics, history=out["history"], artifacts=arts)


def _last(values: list) -> float:
    finite = [float(v) for v in values if math.isfinite(float(v))]
    return finite[-1] if finite else 0.0
