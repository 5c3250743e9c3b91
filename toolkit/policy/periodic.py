"""An evaluation of the learner's policy every few PPO iterations, kept with the training.

A task that reports how its deterministic policy does during training (the survival time of a
spacetime motion from several start phases, the share of get-ups from perturbed clip starts)
evaluates the learner's model (``IterationStats.model``) every ``every`` iterations and keeps one
row per evaluation, ``(samples, *values)``, in PPO's ``extra`` under ``key``
(``"eval_history"`` by default). ``extra`` is checkpointed in ``ppo.h5``, so a resumed run
continues the rows where it stopped, and the ``jt study`` tools read them back as
``extra/eval_history``. Each evaluation also draws the progress line (the share of the sample
budget done and the task's message).

``PeriodicEvaluation`` is PPO's ``on_iteration`` hook doing that. What it evaluates is the task's:
pass an ``evaluate(model) -> values`` callable, or subclass it and override ``evaluate`` (a hook
whose evaluation the task also runs on the final policy). A further hook of the task (a start
distribution's update, a curriculum, the per-iteration history) runs first through ``then``; what
it returns is returned, so PPO still applies it to the environments.

Usage, in a task's ``training``::

    def success(model):                         # -> (values,) one per column
        with opened_env(self.env_class, spec, seed=ctx.seed) as env:
            return [share_that_got_up(env, model)]

    hook = PeriodicEvaluation(extra, ("got_up",), every=10, evaluate=success,
                              then=hist.on_iteration, progress=ctx.progress,
                              total=self.sample_budget(ctx),
                              message=lambda v: f"got up {v[0]:.2f}")
    hooks = Hooks(on_iteration=hook, extra=extra, state={"evaluation": hook})
    ...
    hook.history()   # in measure: (n_evaluations, 1 + n_columns)
"""

from __future__ import annotations

from typing import Any, Callable, Optional, Sequence

import numpy as np

KEY = "eval_history"
"""The default entry of PPO's ``extra`` that holds the rows (``extra/eval_history`` in ``ppo.h5``)."""


class PeriodicEvaluation:
    """PPO's ``on_iteration``: every ``every`` iterations, evaluate the learner's model and keep
    the row ``(samples, *values)`` in ``extra[key]``.

    Args:
        extra: PPO's ``extra`` dict (checkpointed; a resumed run's rows are already in it). An
            empty ``(0, 1 + n_columns)`` entry is put there at once, so every checkpoint has it.
        columns: the names of the values an evaluation gives, after ``samples``.
        every: iterations between evaluations (0: none); iteration ``i`` (1-based) is evaluated
            when ``i % every == 0``.
        evaluate: ``evaluate(model) -> values`` (one per column); None: the subclass overrides
            ``evaluate``.
        then: the task's further ``on_iteration(iteration, samples, stats)``, called first; what it
            returns is returned (None: nothing, ``{}`` is returned).
        progress: ``progress(fraction, message)`` after each evaluation, or None.
        total: the run's sample budget, for the progress fraction.
        message: ``message(values) -> str``, the progress line's text (None: empty).
        key: the entry of ``extra``.
    """

    def __init__(self, extra: dict, columns: Sequence[str], every: int,
                 evaluate: Optional[Callable[[Any], Sequence[float]]] = None,
                 then: Optional[Callable[[int, int, Any], Any]] = None, progress: Optional[Callable] = None,
                 total: int = 1, message: Optional[Callable[[Sequence[float]], str]] = None,
                 key: str = KEY) -> None:
        self.extra, self.columns, self.every, self.key = extra, tuple(columns), int(every), key
        self.evaluation, self.then, self.progress = evaluate, then, progress
        self.total, self.message = max(int(total), 1), message
        self.extra.setdefault(self.key, np.zeros((0, 1 + len(self.columns))))

    def __call__(self, iteration: int, samples: int, stats: Any) -> Any:
        """PPO's ``on_iteration``: ``then`` first, then the evaluation when one is due (the learner's
        model is ``stats.model``; without one, nothing is evaluated)."""
        out = self.then(iteration, samples, stats) if self.then is not None else {}
        model = getattr(stats, "model", None)
        if self.every > 0 and model is not None and iteration % self.every == 0:
            values = [float(v) for v in self.evaluate(model)]
            if len(values) != len(self.columns):
                raise ValueError(f"{self.key}: an evaluation gave {len(values)} values for the columns "
                                 f"{', '.join(self.columns)}")
            self.extra[self.key] = np.vstack([self.history(), [float(samples), *values]])
            if self.progress is not None:
                self.progress(min(samples / self.total, 1.0), self.message(values) if self.message else "")
        return out

    def evaluate(self, model: Any) -> Sequence[float]:
        """One evaluation of ``model``: one value per column (the ``evaluate`` callable given).

        Raises:
            NotImplementedError: no callable was given and the subclass does not override it.
        """
        if self.evaluation is None:
            raise NotImplementedError(f"{type(self).__name__}: give evaluate= or override evaluate")
        return self.evaluation(model)

    def history(self) -> np.ndarray:
        """The rows ``(n_evaluations, 1 + n_columns)``: samples, then the columns."""
        width = 1 + len(self.columns)
        return np.asarray(self.extra.get(self.key, np.zeros((0, width))), dtype=float).reshape(-1, width)

    def curves(self, names: Optional[dict[str, str]] = None) -> dict[str, list[tuple[int, float]]]:
        """``{name: [(samples, value), ...]}`` per column, for an ``Evaluation``'s history.

        Args:
            names: ``{column: curve name}`` of the columns wanted (None: every column, by its name).
        """
        rows = self.history()
        names = {c: c for c in self.columns} if names is None else dict(names)
        return {names[c]: [(int(r[0]), float(r[i])) for r in rows]
                for i, c in enumerate(self.columns, start=1) if c in names}
