"""What ``task=spacetime`` does after every PPO iteration (``on_iteration``).

* The start distribution (002 §4.3, ``sampling.StartSampler``): eq 11 start-phase weights and
  eq 12 start-state buffers, sent to every env as ``start_sampling``.
* Table 1's evaluation during training: every ``eval_every`` iterations (10, authors' code), the
  deterministic policy (the learner's model after the iteration) runs from ``eval_starts`` start
  phases spread evenly from ``eval_phase`` (the authors average several episodes from random
  phases) with bounds off, up to ``eval_time_limit`` (20 s), failing only on a forbidden ground
  contact (the final rollout's set-up); ``(samples, mean survival_s, share survived, min
  survival_s)`` rows go to ``extra["eval_history"]`` (checkpointed, so a resumed run keeps them).
  ``samples_to_20s`` is the first sample count at which every start reached the time limit (the
  mean is 20 s: 002 Table 1's N_s).
"""

from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

from toolkit.execution import stopping

EVAL_KEY = "eval_history"


class SpacetimeTraining:
    """PPO's ``on_iteration`` of ``task=spacetime``.

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
        self.eval_every, self.extra, self.progress, self.total = int(eval_every), extra, progress, max(int(total), 1)
        self.extra.setdefault(EVAL_KEY, np.zeros((0, 4)))

    def __call__(self, iteration: int, samples: int, stats: Any) -> dict[str, Any]:
        out = self.sampler.update(iteration, samples, stats) if self.sampler is not None else {}
        model = getattr(stats, "model", None)
        if self.eval_every > 0 and model is not None and iteration % self.eval_every == 0:
            survival, survived, worst = self.evaluate(model)
            self.extra[EVAL_KEY] = np.vstack([self.history(), [float(samples), survival, survived, worst]])
            if self.progress is not None:
                self.progress(min(samples / self.total, 1.0), f"survival {survival:.2f} s (min {worst:.2f})")
        return out

    def phases(self) -> list[float]:
        """The evaluation's start phases ``eval_phase + k / n_starts`` (mod 1)."""
        p0 = float(self.options.get("phase") or 0.0)
        return [(p0 + k / self.n_starts) % 1.0 for k in range(self.n_starts)]

    def evaluate(self, model: Any) -> tuple[float, float, float]:
        """``(mean survival_s, share survived, min survival_s)`` of the deterministic policy from
        each of ``phases()``."""
        env = self.make_env()
        out = []
        try:
            for phase in self.phases():
                stopping.check()  # a safe point (SIGTERM): between the evaluation's episodes
                obs, _ = env.reset(seed=0, options={**self.options, "phase": phase})
                info: dict = {}
                done, steps = False, 0
                while not done:
                    obs, _, te, tr, info = env.step(model.act(obs).astype(np.float32))
                    steps += 1
                    done = te or tr
                out.append((float(info.get("survival_s", steps / env.control_hz)),
                            float(bool(info.get("time_out", 0.0)))))
        finally:
            env.close()
        s = np.array(out)
        return float(s[:, 0].mean()), float(s[:, 1].mean()), float(s[:, 0].min())

    def history(self) -> np.ndarray:
        """Rows ``(samples, mean survival_s, share survived, min survival_s)`` ``(n_evaluations, 4)``."""
        return np.asarray(self.extra.get(EVAL_KEY, np.zeros((0, 4))), dtype=float).reshape(-1, 4)


def samples_to_20s(rows: np.ndarray) -> Optional[float]:
    """The first sample count at which every start of the evaluation survived, or None."""
    rows = np.asarray(rows, dtype=float).reshape(len(rows), -1)
    hit = np.flatnonzero(rows[:, 2] >= 1.0 - 1e-9)
    return float(rows[hit[0], 0]) if hit.size else None
