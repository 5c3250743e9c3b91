"""What ``task=spacetime`` does after every PPO iteration (``on_iteration``).

* The start distribution (002 §4.3, ``sampling.StartSampler``): eq 11 start-phase weights and
  eq 12 start-state buffers, sent to every env as ``start_sampling``.
* Table 1's evaluation during training: every ``eval_every`` iterations (10, authors' code), the
  deterministic policy (the learner's model after the iteration) runs from ``eval_starts`` start
  phases spread evenly from ``eval_phase`` (the authors average several episodes from random
  phases) with bounds off, up to ``eval_time_limit`` (20 s), failing only on a forbidden ground
  contact (the final rollout's set-up); ``(samples, mean survival_s, share survived, min
  survival_s)`` rows go to ``extra["eval_history"]`` (checkpointed, so a resumed run keeps them:
  ``toolkit.policy.periodic.PeriodicEvaluation``).
  ``samples_to_20s`` is the first sample count at which every start reached the time limit (the
  mean is 20 s: 002 Table 1's N_s).
"""

from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

from toolkit.policy.episodes import opened_env, rollout
from toolkit.policy.periodic import PeriodicEvaluation

COLUMNS = ("survival_s", "survived", "survival_min_s")  #: an evaluation's row, after its samples


class SpacetimeTraining(PeriodicEvaluation):
    """PPO's ``on_iteration`` of ``task=spacetime``: the start sampler's update every iteration,
    Table 1's evaluation every ``eval_every`` (rows ``(samples, mean survival_s, share survived,
    min survival_s)``, ``history()`` ``(n_evaluations, 4)``).

    Args:
        sampler: the ``StartSampler`` (None: uniform starts, nothing sent).
        make_env: ``make_env() -> SpacetimeEnv`` for the evaluations (built and closed each time).
        options: the evaluation's reset options (``{"phase": eval_phase, "evaluate": True}``).
        n_starts: start phases of each evaluation, ``eval_phase + k / n_starts`` (mod 1).
        eval_every: iterations between evaluations (0: none).
        extra: PPO's ``extra`` (the evaluation rows live there).
        progress: optional ``progress(fraction, message)``; total: the run's sample budget.
    """

    def __init__(self, sampler: Any, make_env: Callable[[], Any], options: dict, eval_every: int, extra: dict,
                 progress: Optional[Callable] = None, total: int = 1, n_starts: int = 1) -> None:
        self.sampler, self.make_env, self.options = sampler, make_env, dict(options)
        self.n_starts = max(int(n_starts), 1)
        super().__init__(extra, COLUMNS, eval_every, then=sampler.update if sampler is not None else None,
                         progress=progress, total=total,
                         message=lambda v: f"survival {v[0]:.2f} s (min {v[2]:.2f})")

    def phases(self) -> list[float]:
        """The evaluation's start phases ``eval_phase + k / n_starts`` (mod 1)."""
        p0 = float(self.options.get("phase") or 0.0)
        return [(p0 + k / self.n_starts) % 1.0 for k in range(self.n_starts)]

    def evaluate(self, model: Any) -> tuple[float, float, float]:
        """``(mean survival_s, share survived, min survival_s)`` of the deterministic policy from
        each of ``phases()``."""
        out = []
        with opened_env(self.make_env) as env:
            for phase in self.phases():
                ro = rollout(env, model, options={**self.options, "phase": phase})
                out.append((float(ro.info.get("survival_s", ro.steps / env.control_hz)),
                            float(bool(ro.info.get("time_out", 0.0)))))
        s = np.array(out)
        return float(s[:, 0].mean()), float(s[:, 1].mean()), float(s[:, 0].min())


def samples_to_20s(rows: np.ndarray) -> Optional[float]:
    """The first sample count at which every start of the evaluation survived, or None."""
    rows = np.asarray(rows, dtype=float).reshape(len(rows), -1)
    hit = np.flatnonzero(rows[:, 2] >= 1.0 - 1e-9)
    return float(rows[hit[0], 0]) if hit.size else None
