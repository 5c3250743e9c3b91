"""One deterministic episode of a policy, the record it leaves, and an env that closes itself.

Every policy task measures its trained policy the same way: reset the environment with seed 0 and
the task's reset options, step it with the policy's mean action until the episode terminates or is
truncated, and keep the return and the last step's ``info``. The final rollout of
``PolicyTask.evaluate`` does it once (recording every control step and rendering frames), the
evaluations during training and the studies of a trained policy do it from many starts. This
module is that loop, written once:

* ``rollout(env, model, record, frames, width, height, options)`` runs one such episode and returns
  a ``Rollout``: the return, the last ``info``, the number of control steps, the rendered frames
  and one array per recorded name (``record(env)`` before the first step and after every step).
* ``Rollout`` is the typed record the ``PolicyTask`` hooks read (``retry_rollout``,
  ``rollout_data``, ``measure``); what a task derives from the episode for its ``measure`` (a
  take-off state, style measures ...) goes to its ``notes``.
* ``opened_env(factory, *args, **kwargs)`` builds an environment and closes it however the block
  ends (``with opened_env(task.env_class, spec, seed=0) as env: ...``).

Usage::

    with opened_env(task.env_class, spec, seed=0) as env:
        ro = rollout(env, model, options={"phase": 0.25})
    ro.return_, ro.steps, ro.info.get("reason")
"""

from __future__ import annotations

import contextlib
import dataclasses
from typing import Any, Callable, Iterator, Optional

import numpy as np


@dataclasses.dataclass
class Rollout:
    """One deterministic episode of a policy (``rollout``).

    Attributes:
        return_: the episode's return, the sum of its rewards (``return`` is Python's keyword).
        info: the last step's ``info`` (why the episode ended, the task's episode figures).
        steps: control steps taken.
        frames: the rendered frames ``(height, width, 3 or 4)``, one per recorded state
            (``steps + 1``), or none when ``rollout`` was asked for no frames.
        series: one array per name that ``record(env)`` gave, ``(steps + 1, ...)``: the state
            before the first step, then after every step (empty without ``record``).
        notes: what a task derives from the episode for its ``measure`` (``rollout_data`` writes
            them: a final state, the reference's frames ...); empty from ``rollout``.
    """

    return_: float
    info: dict[str, Any]
    steps: int
    frames: list = dataclasses.field(default_factory=list)
    series: dict[str, np.ndarray] = dataclasses.field(default_factory=dict)
    notes: dict[str, Any] = dataclasses.field(default_factory=dict)

    @property
    def time(self) -> np.ndarray:
        """Time of every recorded state ``(steps + 1,)`` (s; ``PolicyTask.record``'s ``time``)."""
        return self.series["time"]

    @property
    def root(self) -> np.ndarray:
        """Root pose of every recorded state ``(steps + 1, 7)`` (position, quaternion xyzw)."""
        return self.series["root"]

    @property
    def com(self) -> np.ndarray:
        """Centre of mass of every recorded state ``(steps + 1, 3)`` (m, world)."""
        return self.series["com"]


def rollout(env: Any, model: Any, record: Optional[Callable[[Any], dict]] = None, frames: int = 0,
            width: int = 160, height: int = 120, options: Optional[dict] = None,
            max_steps: Optional[int] = None) -> Rollout:
    """One deterministic episode (the policy's mean action) from ``env.reset(seed=0, options)``.

    A safe point comes first (``toolkit.execution.stopping.check``): a stop asked for between
    the episodes of an evaluation stops it there.

    Args:
        env: the environment (``gymnasium.Env`` API; ``render_frame(width, height)`` when
            ``frames > 0``).
        model: the policy: ``act(obs (obs_dim,)) -> (act_dim,)``, its mean action.
        record: ``record(env) -> {name: value}`` before the first step and after every step
            (None: nothing recorded).
        frames: render every recorded state when > 0 (``frames`` of them go to a filmstrip).
        width, height: frame size (px).
        options: the reset options (a start time, a start phase, a curve ...).
        max_steps: stop after this many control steps even if the episode goes on (``jt play
            --seconds``); None: until it terminates or is truncated.

    Returns:
        The ``Rollout``: ``return_``, ``info``, ``steps``, ``frames`` and, per recorded name, an
        array ``(steps + 1, ...)`` in ``series``.
    """
    from toolkit.execution import stopping

    stopping.check()  # a safe point (SIGTERM): between the episodes of an evaluation
    obs, _ = env.reset(seed=0, options=options)
    rows: list[dict] = []
    imgs: list[np.ndarray] = []
    done, ret, info, steps = False, 0.0, {}, 0

    def snap() -> None:
        if record is not None:
            rows.append(record(env))
        if frames > 0:
            imgs.append(env.render_frame(width, height))

    snap()
    while not done and (max_steps is None or steps < max_steps):
        obs, r, te, tr, info = env.step(model.act(obs).astype(np.float32))
        ret += r
        steps += 1
        done = te or tr
        snap()
    series = {key: np.array([row[key] for row in rows]) for key in rows[0]} if rows else {}
    return Rollout(return_=ret, info=info, steps=steps, frames=imgs, series=series)


@contextlib.contextmanager
def opened_env(factory: Callable[..., Any], *args: Any, **kwargs: Any) -> Iterator[Any]:
    """The environment ``factory(*args, **kwargs)``, closed when the block ends (also on an error
    or a stop request).

    Args:
        factory: builds the environment (an env class, ``task.make_env``, a ``functools.partial``).
        *args, **kwargs: its arguments (e.g. the spec and ``seed=0``).

    Yields:
        The environment.
    """
    env = factory(*args, **kwargs)
    try:
        yield env
    finally:
        env.close()
