"""``task=standing_jump``: Pareto-optimal standing jumps, natural and supernatural (``004``).

One evaluation simulates one in-place standing jump of the planar 17-link humanoid with the
finite-state controller of ``004`` §3.1, parameterised by the 34 free parameters of §3 (phase
target angles plus the two gravity-assist parameters of §3.3), and returns the two objectives
RMOO trades off (§4.2): jump height (as ``-height``, everything is minimised) and the effort
``log(w_JE e_JE + w_SE e_SE)`` (§4.3.2). ``summarize`` writes the samples and the front with the
columns of Tables 2–3, a Fig. 8-style plot, and filmstrips of the lowest and highest natural and
the highest supernatural jump.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any, ClassVar, Sequence

from toolkit.interfaces.plugin import Plugin
from toolkit.interfaces.searcher import SearchProblem
from toolkit.interfaces.task import EvalContext, Evaluation, Task
from toolkit.config import group_of, task_params


def _spd_group(cfg: Any) -> dict:
    """The run config's ``spd`` group as a plain dict; ``{"name": "maba"}`` when it has none."""
    group = group_of(cfg, "spd")
    if group is None:
        return {"name": "maba"}
    name = str(group["name"]) if "name" in group else "maba"
    return {"name": name, **Plugin.params_of(group)}


class StandingJumpTask(Task):
    """Standing jump of a planar humanoid: jump height vs effort, natural and supernatural (004)."""

    ignores_groups: ClassVar[tuple[str, ...]] = ("action", "reward", "curriculum")
    needs_spd_torques: ClassVar[bool] = True  #: it adds the virtual-force torques and applies the limits itself

    key_metrics: ClassVar[tuple[str, ...]] = ("hypervolume", "max_natural_height", "max_height", "n_front")
    #: ``jt study standing_jump TOOL``: the analysis tools (``jt_tasks.standing_jump.analysis``)
    studies: ClassVar[dict[str, str]] = {"hypervolume": "jt_tasks.standing_jump.analysis.study:main",
                                         "bench": "jt_tasks.standing_jump.analysis.bench:main"}

    @dataclasses.dataclass
    class Config:
        name: str = "standing_jump"
        sim_hz: float = 600.0
        """Simulation = control rate, Hz, with Stable PD (004 uses Vortex and gives no rate; 600 Hz as 000/001)."""
        mass: float = 80.0
        """Kg (004 §3: "weighs 80 kg")."""
        height: float = 1.60
        """M (004 §3: "160 cm tall")."""
        friction: float = 1.0
        """Foot-ground Coulomb friction (our choice)."""
        gains_scale: float = 1.0
        """Factor on the fixed, hand-tuned PD gains (004 §3)."""
        max_time: float = 6.0
        """Longest episode, s (our choice)."""
        landing_target: float = 0.0
        """L_o, m: an in-place jump lands where it started (004 §3.2, eq 3)."""
        landing_tolerance: float = 0.25
        """L_r, m: landing bracket (004 eq 3; the paper gives no value)."""
        upright_fraction: float = 0.8
        """Head above 0.8 × standing head height at the end, else a fall (our choice)."""
        w_je: float = 1.0
        """W_JE (004 §4.3.2)."""
        w_se: float = 5000.0
        """W_SE: w_SE / w_JE = 5000 (004 §4.3.2)."""
        w_p: float = 5000.0
        """C_H weight (004 §3.2, eq 2: "a value of 5000 for w_p")."""
        f_p: float = 1.0e5
        """Failure penalty (004 §3.2, eq 3: "f_p was set to ... 100000")."""
        assist_deadzone: float = 0.05
        """M/s²: smaller assists are exactly none (natural jumps use 0 force, 004 §5)."""
        default_gravity: float = -11.0
        """Take-off gravity of the seed controller (≤ -9.8 = natural; 004 §3.3)."""
        default_assist_time: float = 0.5
        """S, seed assist duration (irrelevant while natural; 004 Tables 2-3: 0.27-0.82 s)."""
        save_trajectory: bool = True
        """Jump.h5 per evaluation (CoM, head, angular momentum at 100 Hz; events)."""
        filmstrips: bool = True
        """Summarize: filmstrips of lowest/highest natural and highest supernatural (004 Fig. 9)."""
        filmstrip_width: int = 320
        """Px per frame (at least 320: a picture shows the jumper at every budget)."""
        filmstrip_height: int = 480
        """Px per frame."""

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        self.params = task_params(self.Config, cfg)
        self.spd = _spd_group(cfg)  # SPD backend (spd=maba|df|sf|pcg), maba without an spd group

    # ---- the search problem -------------------------------------------------------------------
    def settings(self) -> Any:
        """Simulation settings from the config."""
        from jt_tasks.standing_jump.timing import Timing
        from jt_tasks.standing_jump.simulate import SimSettings

        c = self.params
        return SimSettings(sim_hz=c.sim_hz, mass=c.mass, height=c.height, friction=c.friction,
                           timing=Timing(gains_scale=c.gains_scale), max_time=c.max_time,
                           upright_fraction=c.upright_fraction, landing_target=c.landing_target,
                           landing_tolerance=c.landing_tolerance, assist_deadzone=c.assist_deadzone,
                           spd=dict(self.spd))

    def reference_point(self) -> list[float]:
        """Hypervolume reference: standing head height (no jump) and an unreachable effort."""
        from jt_tasks.standing_jump import objectives as O
        from jt_tasks.standing_jump import params as P
        from jt_tasks.standing_jump.controller import GAINS
        from jt_tasks.standing_jump.model import build_body, effort_weights, standing_head_height

        c = self.params
        body = build_body(c.mass, c.height)
        w = effort_weights(body)
        limits = {link.joint: GAINS[link.joint_class][2] for link in body.links[1:]}
        bound = O.effort_bound(limits, w, c.max_time, c.mass, P.GRAVITY_BOUNDS[1] - P.NATURAL_GRAVITY,
                               P.ASSIST_TIME_BOUNDS[1], c.w_je, c.w_se)
        return [-standing_head_height(body), math.ceil(bound)]

    def problem(self) -> SearchProblem:
        from jt_tasks.standing_jump import params as P

        return SearchProblem(space=P.space(self.params.default_gravity, self.params.default_assist_time),
                             n_objectives=2, objective_names=("neg_height", "effort"),
                             reference_point=self.reference_point())

    # ---- one evaluation -----------------------------------------------------------------------
    def evaluate(self, point: dict[str, float], ctx: EvalContext) -> Evaluation:
        from jt_tasks.standing_jump import objectives as O
        from jt_tasks.standing_jump.simulate import simulate

        c = self.params
        trace: list = [] if c.save_trajectory else None
        ctx.report(0.0, "simulating")
        r = simulate(point, self.settings(), trace=trace)
        failed = not r.success
        objs = O.jump_objectives(r.height, r.e_je, r.e_se, failed, c.w_je, c.w_se, c.f_p)
        metrics = {
            "height": r.height,
            "com_height": r.com_height,
            "internal_energy": r.e_je,
            "external_energy": r.e_se,
            "effort": O.effort(r.e_je, r.e_se, c.w_je, c.w_se),
            "takeoff_gravity": r.takeoff_gravity,
            "force_application_time": r.assist_time,
            "natural": float(r.natural),
            "success": float(r.success),
            "landing_x": r.landing_x,
            "flight_time": r.flight_time,
            "liftoff_velocity": r.liftoff_velocity,
            "liftoff_momentum": r.liftoff_momentum,
            "sim_time": r.sim_time,
        }
        if trace is not None:
            self._save(Path(ctx.workdir) / "jump.h5", point, r, trace)
        ctx.report(1.0, "done")
        return Evaluation(metrics=metrics, objectives=objs, failed=failed, reason=r.reason)

    def _save(self, path: Path, point: dict[str, float], r: Any, trace: list) -> None:
        import numpy as np

        from toolkit.store import h5

        rows = trace[:: max(int(self.params.sim_hz // 100), 1)]  # 100 Hz
        cols = np.array([row[2:] for row in rows], dtype=float).reshape(-1, 7)
        h5.write(path, {
            "point": {k: float(v) for k, v in point.items()},
            "events": {"phase": np.array([e[0] for e in r.events]), "time": np.array([e[1] for e in r.events])},
            "trajectory": {"time": np.array([row[0] for row in rows]), "com_x": cols[:, 0], "com_z": cols[:, 1],
                           "com_vx": cols[:, 2], "com_vz": cols[:, 3], "pelvis_pitch": cols[:, 4],
                           "chest_pitch": cols[:, 5], "angular_momentum": cols[:, 6]},
        }, attrs={"format": "jt.standing_jump/1", "reason": r.reason})

    # ---- the run ------------------------------------------------------------------------------
    def summarize(self, evaluations: Sequence[Evaluation], workdir: Path) -> dict[str, float]:
        from jt_tasks.standing_jump.summary import summarize

        return summarize(self, evaluations, Path(workdir))
