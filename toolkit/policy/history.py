"""What every policy task keeps per PPO iteration and reports: one mechanism, not one per task.

``IterationHistory`` is the training curve a task adds to PPO's: one row per iteration,
``(samples, value, ...)``, each value a mean over the iteration's finished episodes (their final
``info``) or anything the task computes; the rows live in PPO's ``extra`` under the task's key, so
they are checkpointed in ``ppo.h5`` and a resumed run continues the curve. It also draws the
evaluation's progress line with the task's key figure. ``measured`` is what every task's
``measure`` starts from: its own metrics, the ones every policy task reports (``base_metrics``:
the deterministic rollout's return and PPO's counters), only the finite ones, and the training
curve (``mean_return``) beside the task's curves; ``numbers`` and ``finite`` are the rest of the
metric plumbing.

Usage, in a task's ``training`` hook::

    hist = IterationHistory(extra, "goal_history", ("r_goal", "took_off"), total, ctx.progress,
                            shown=("r_goal", ".3f"))
    hooks = Hooks(on_iteration=hist.on_iteration, extra=extra)
    ...
    hist.curves(result.extra, {"r_goal": "goal_reward"})   # in measure: {name: [(samples, v)]}

and in its ``measure``::

    metrics, history = measured(ro, trained, {"goal_reward": ro.info["r_goal"]},
                                hist.curves(trained.result.extra))
    return Evaluation(metrics=metrics, history=history)
"""

from __future__ import annotations

import math
from typing import Any, Callable, Mapping, Optional, Sequence

import numpy as np


def mean_of(episodes: Sequence[Mapping[str, Any]], key: str) -> float:
    """Mean of ``key`` over episode infos (a missing key counts 0); nan without an episode."""
    return float(np.mean([float(e.get(key, 0.0)) for e in episodes])) if episodes else math.nan


def numbers(info: Mapping[str, Any]) -> dict[str, float]:
    """The numeric entries of an episode's ``info`` as floats (for ``rollout.h5``'s ``info``)."""
    return {k: float(v) for k, v in info.items() if isinstance(v, (int, float))}


def finite(metrics: Mapping[str, float]) -> dict[str, float]:
    """``metrics`` without its nan / inf values (the store logs finite numbers only)."""
    return {k: float(v) for k, v in metrics.items() if math.isfinite(float(v))}


def base_metrics(ro: Any, trained: Any) -> dict[str, float]:
    """The metrics every policy task reports: the deterministic rollout's return and PPO's counters.

    Args:
        ro: the deterministic rollout (``toolkit.policy.episodes.Rollout``), its ``return_``.
        trained: ``toolkit.policy.train.Trained``.

    Returns:
        ``mean_return``, ``train_mean_return`` (the last finite training mean), ``samples``,
        ``iterations``, ``samples_per_s``, ``train_wall_s``.
    """
    from toolkit.policy.train import last_finite

    res = trained.result
    return {"mean_return": float(ro.return_),
            "train_mean_return": last_finite(res.history.get("mean_return", [])),
            "samples": float(res.samples), "iterations": float(res.iterations),
            "samples_per_s": float(trained.samples_per_s), "train_wall_s": float(trained.wall_s)}


def time_breakdown(trained: Any, clock: list[float]) -> dict[str, float]:
    """Where an evaluation's wall time went (s), as ``wall_*_s`` metrics (``jt bench evaluation``).

    Args:
        trained: ``toolkit.policy.train.Trained`` (its PPO history holds ``collect_s``,
            ``update_s`` and ``hook_s`` per iteration; its result ``startup_s`` and ``checkpoint_s``).
        clock: ``perf_counter`` readings: before the final rollout, after it, after its pictures
            and ``rollout.h5`` were written, after the task's ``measure``.

    Returns:
        ``wall_startup_s``, ``wall_collect_s``, ``wall_update_s``, ``wall_hooks_s`` (the task's
        per-iteration hook: a curriculum's deterministic rollouts), ``wall_checkpoint_s``; then
        ``wall_final_rollout_s``, ``wall_pictures_s``, ``wall_measure_s``.
    """
    res, hist = trained.result, trained.result.history

    def total(key: str) -> float:
        return float(np.nansum(np.asarray(hist.get(key, []), dtype=np.float64)))

    return {"wall_startup_s": float(getattr(res, "startup_s", 0.0)),
            "wall_collect_s": total("collect_s"), "wall_update_s": total("update_s"),
            "wall_hooks_s": total("hook_s"), "wall_checkpoint_s": float(getattr(res, "checkpoint_s", 0.0)),
            "wall_final_rollout_s": clock[1] - clock[0], "wall_pictures_s": clock[2] - clock[1],
            "wall_measure_s": clock[3] - clock[2]}


def measured(ro: Any, trained: Any, metrics: Mapping[str, float],
             curves: Optional[Mapping[str, list]] = None,
             keep_nonfinite: bool = False) -> tuple[dict[str, float], dict[str, list]]:
    """A policy task's metrics and curves: its own, then what every policy task reports.

    Args:
        ro: the deterministic rollout (``toolkit.policy.episodes.Rollout``).
        trained: ``toolkit.policy.train.Trained``.
        metrics: the task's own metrics (first, in their order: the progress line shows the
            first few).
        curves: the task's own curves ``{name: [(samples, value, ...)]}`` (None: none).
        keep_nonfinite: keep nan / inf metrics (default: ``finite`` drops them).

    Returns:
        ``(metrics, history)``: ``metrics`` followed by ``base_metrics(ro, trained)``, finite
        only unless ``keep_nonfinite``; ``history`` is ``mean_return`` (``return_curve``, the
        training curve against samples) followed by ``curves``.
    """
    from toolkit.policy.train import return_curve

    out = {**metrics, **base_metrics(ro, trained)}
    return (out if keep_nonfinite else finite(out)), {"mean_return": return_curve(trained), **dict(curves or {})}


class IterationHistory:
    """Per-iteration rows ``(samples, *columns)`` in PPO's ``extra[key]``, and the progress line.

    Args:
        extra: PPO's ``extra`` dict (checkpointed; a resumed run's rows are already in it).
        key: the entry of ``extra`` (e.g. ``"goal_history"``).
        columns: the row's value names, after ``samples``.
        total_samples: the budget, for the progress fraction.
        progress: ``progress(fraction, message)`` or None.
        row: ``row(episodes, stats) -> values`` (one per column); default: each column's
            ``mean_of`` over the iteration's finished episodes.
        shown: ``(column, format)`` of the figure on the progress line, or ``(column, format,
            missing)`` with the text shown while it is nan; None: no figure.
        then: a further ``on_iteration(it, samples, stats)`` (e.g. a curriculum's), called first;
            what it returns is returned (PPO applies it to the envs).
    """

    def __init__(self, extra: dict, key: str, columns: Sequence[str], total_samples: int,
                 progress: Optional[Callable] = None,
                 row: Optional[Callable[[list, Any], Sequence[float]]] = None,
                 shown: Optional[tuple] = None, then: Optional[Callable] = None) -> None:
        self.extra, self.key, self.columns = extra, key, tuple(columns)
        self.total, self.progress, self.row, self.shown, self.then = int(total_samples), progress, row, shown, then

    def rows(self, extra: Optional[Mapping] = None) -> np.ndarray:
        """The rows ``(n_iterations, 1 + n_columns)`` in ``extra`` (default: the bound one)."""
        width = 1 + len(self.columns)
        saved = np.asarray((self.extra if extra is None else extra).get(self.key, np.zeros((0, width))),
                           dtype=np.float64)
        return saved.reshape(-1, width) if saved.size else np.zeros((0, width))

    def on_iteration(self, it: int, samples: int, stats: Any) -> Any:
        """PPO's ``on_iteration``: append this iteration's row, report progress."""
        out = self.then(it, samples, stats) if self.then is not None else None
        eps = list(getattr(stats, "episodes", []) or [])
        values = self.row(eps, stats) if self.row is not None else [mean_of(eps, c) for c in self.columns]
        row = [float(samples)] + [float(v) for v in values]
        self.extra[self.key] = np.vstack([self.rows(), [row]])
        if self.progress is not None:
            self.progress(min(samples / max(self.total, 1), 1.0), self.message(row))
        return out

    def message(self, row: Sequence[float]) -> str:
        """The progress line's figure for ``row`` (empty without ``shown``)."""
        if self.shown is None:
            return ""
        from toolkit.execution.progress import figure

        column, fmt, *missing = self.shown
        value = row[1 + self.columns.index(column)]
        return f"{column} {figure(value, fmt, *missing)}"

    def curves(self, extra: Mapping, names: Optional[Mapping[str, str]] = None,
               prefix: str = "") -> dict[str, list[tuple[int, float]]]:
        """``{name: [(samples, value), ...]}`` per column (finite values only), for an
        ``Evaluation``'s history; ``names`` renames columns, ``prefix`` goes before the others."""
        rows = self.rows(extra)
        names = dict(names or {})
        return {names.get(c, prefix + c): [(int(r[0]), float(r[i])) for r in rows if math.isfinite(r[i])]
                for i, c in enumerate(self.columns, start=1)}
