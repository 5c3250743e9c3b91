"""The function every executor runs: build the task from the config and evaluate one point.

It is module-level (so it pickles for process pools and Ray) and caches the task per process, so
a worker that evaluates many points builds its task once.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import sys
import time
from typing import Any

from toolkit.interfaces import EvalContext, Evaluation

_TASKS: dict[str, Any] = {}


@dataclasses.dataclass
class Job:
    """One evaluation to run.

    Attributes:
        config: the run config as a plain container (picklable).
        point: parameter values by name.
        ctx: where and how to run it (index, seed, workdir).
        verbose: print progress lines to stderr (evaluations that run longer than ``QUIET_S``)
            when there is no ``channel``.
        channel: where progress goes, ``channel(index, fraction, message)``: the run's
            ``progress.RunProgress.update`` in the driver's process, or a ``progress.Channel`` onto
            the executor's queue in a worker.
    """

    config: dict
    point: dict[str, float]
    ctx: EvalContext
    verbose: bool = False
    channel: Any = None


def _task_for(config: dict) -> Any:
    key = hashlib.sha1(json.dumps(config, sort_keys=True, default=str).encode()).hexdigest()
    task = _TASKS.get(key)
    if task is None:
        from omegaconf import OmegaConf

        from toolkit import plugins
        from toolkit.config import validate

        cfg = validate(OmegaConf.create(config))
        task = plugins.load("task", str(cfg.task.name))(cfg)
        _TASKS[key] = task
    return task


QUIET_S = 2.0  #: an evaluation reports progress only once it has run this long (short ones stay quiet)


def _printer(index: int) -> Any:
    start = time.monotonic()
    last = [start]

    def progress(fraction: float, message: str = "") -> None:
        now = time.monotonic()
        if now - start >= QUIET_S and (now - last[0] >= 1.0 or fraction >= 1.0):
            last[0] = now
            print(f"  eval {index}: {100 * fraction:5.1f}% {message}", file=sys.stderr, flush=True)

    return progress


def run_job(job: Job) -> tuple[Evaluation, float]:
    """Evaluate one point; returns the evaluation and the seconds it took."""
    from toolkit.execution.seeds import seed_everything

    seed_everything(job.ctx.seed)
    task = _task_for(job.config)
    ctx = job.ctx
    if ctx.progress is None and job.channel is not None:
        import functools

        ctx = dataclasses.replace(ctx, progress=functools.partial(job.channel, ctx.index))
    elif job.verbose and ctx.progress is None:
        ctx = dataclasses.replace(ctx, progress=_printer(ctx.index))
    t0 = time.perf_counter()
    ev = task.evaluate(dict(job.point), ctx)
    ev.point = dict(job.point)
    return ev, time.perf_counter() - t0
