"""The run-up's training hooks and its deterministic rollout's start (``000`` §6.1.1).

Training is the shared policy-task training (``jt_tasks.policy``) to ``agent.total_samples``; the
run-up adds the per-iteration means of its finished episodes' ``r_goal``, mean imitation reward
and take-off rate (checkpointed in PPO's ``extra`` as ``goal_history``, so a resume continues
them). The deterministic run-up starts ``eval_lead`` before the take-off foot's mid-support, or a
whole number of strides before it (``eval_start``).
"""

from __future__ import annotations

import math
from typing import Any, Optional

import numpy as np

from jt_tasks.policy.task import Hooks

HISTORY_KEYS = ("r_goal", "r_imitation_mean", "took_off")  #: per-iteration means of finished episodes


def eval_start(env: Any, eval_lead: Optional[float]) -> float:
    """Clip time the deterministic rollout starts at.

    ``None``: the take-off foot's mid-support itself, so the run-up lasts exactly ``n_strides``
    cycles; else ``eval_lead`` seconds before it (the run-up lasts ``eval_lead`` plus
    ``n_strides - 1`` cycles).
    """
    return float(env.ref.t_mid - (0.0 if eval_lead is None else float(eval_lead)))


def goal_hooks(total_samples: int, progress: Optional[Any]) -> Hooks:
    """PPO hooks of one run-up evaluation (the ``goal_history`` curve, progress)."""
    extra: dict[str, Any] = {}

    def on_iteration(it: int, samples: int, stats: Any) -> None:
        eps = getattr(stats, "episodes", []) or []
        row = [float(samples)] + [float(np.mean([e.get(k, 0.0) for e in eps])) if eps else math.nan
                                  for k in HISTORY_KEYS]
        prev = np.asarray(extra.get("goal_history", np.zeros((0, 4))), dtype=np.float64).reshape(-1, 4)
        extra["goal_history"] = np.vstack([prev, [row]])
        if progress is not None:
            from toolkit.execution.progress import figure

            progress(min(samples / max(total_samples, 1), 1.0), f"r_goal {figure(row[1], '.3f')}")

    return Hooks(on_iteration=on_iteration, extra=extra)


def goal_curves(result: Any) -> dict[str, list]:
    """``goal_reward``, ``imitation_reward`` and ``takeoff_rate`` against samples."""
    goal_hist = np.asarray(result.extra.get("goal_history", np.zeros((0, 4))), dtype=np.float64).reshape(-1, 4)
    return {key: [(int(r[0]), float(r[col])) for r in goal_hist if math.isfinite(r[col])]
            for col, key in enumerate(("goal_reward", "imitation_reward", "takeoff_rate"), start=1)}
