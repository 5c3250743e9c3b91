"""Training a policy task's policy and writing what its deterministic rollout shows, shared by every one.

``train_policy`` trains PPO (``toolkit.rl.ppo.train``) on a task's environments with the ``agent``
group's hyper-parameters, in the evaluation's folder (``ppo.h5``, so a killed evaluation resumes),
opening the ``executor`` for ``agent.n_workers > 1`` and closing it again; ``agent_config`` is
that group's ``PPOConfig`` (its ``total_samples`` is the evaluation's budget). The trained
policy's deterministic episode is ``toolkit.policy.episodes.rollout``; ``save_motion`` writes its
frames as ``filmstrip.png`` (a few frames side by side) and ``motion.gif`` (every frame);
``return_curve`` is the training curve against samples.
"""

from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

CHECKPOINT = "ppo.h5"  #: the policy's checkpoint in an evaluation's folder


class EnvFactory:
    """Picklable ``env_fn(seed) -> env`` for PPO's rollout workers.

    Args:
        env_class: a ``CharacterEnv`` subclass (module-level, so it pickles by reference).
        spec: its picklable spec.
    """

    def __init__(self, env_class: type, spec: Any) -> None:
        self.env_class, self.spec = env_class, spec

    def __call__(self, seed: int) -> Any:
        return self.env_class(self.spec, seed=seed)


def agent_config(agent: Any, seed: int) -> Any:
    """``PPOConfig`` of the ``agent`` group (None: the defaults) with the evaluation's ``seed``.

    Raises:
        JtError: an unknown key, a wrong type or a value out of range (one line).
    """
    from toolkit.config import config_of
    from toolkit.rl.config import PPOConfig

    cfg = config_of(PPOConfig, agent, "agent")
    return dataclasses.replace(cfg, policy_hidden=tuple(int(v) for v in cfg.policy_hidden),
                               value_hidden=tuple(int(v) for v in cfg.value_hidden), seed=int(seed))


@dataclasses.dataclass
class Trained:
    """What ``train_policy`` returns.

    Attributes:
        result: PPO's ``TrainResult`` (model, counters, per-iteration history, ``extra``).
        config: the ``PPOConfig`` trained with.
        wall_s: wall time of the training (s).
        checkpoint: the ``ppo.h5`` written.
    """

    result: Any
    config: Any
    wall_s: float
    checkpoint: Path

    @property
    def samples_per_s(self) -> float:
        """Mean collection + update throughput over the iterations (NaN before any)."""
        sps = self.result.history.get("samples_per_s", [])
        return float(np.mean(sps)) if sps else math.nan


def train_policy(env_fn: Callable[[int], Any], agent: Any, executor: Any, workdir: Path, seed: int,
                 on_iteration: Optional[Callable] = None, extra: Optional[dict] = None,
                 should_stop: Optional[Callable[[], bool]] = None, warm_start: Optional[Path] = None,
                 configure: Optional[Callable[[Any], Any]] = None) -> Trained:
    """Train (or resume) a policy in ``workdir/ppo.h5``.

    Args:
        env_fn: ``env_fn(seed) -> env``.
        agent: the ``agent`` group.
        executor: the ``executor`` group (its plugin holds the rollout workers when
            ``agent.n_workers > 1``), or None.
        workdir: the evaluation's folder.
        seed: the evaluation seed.
        on_iteration, extra, should_stop: PPO's hooks (``toolkit.rl.ppo.train``).
        warm_start: a PPO checkpoint whose networks (and their sizes) a fresh run starts from.
        configure: a last change of the ``PPOConfig`` (e.g. a task's own budget rule).
    """
    from toolkit import plugins
    from toolkit.rl import ppo

    cfg = agent_config(agent, seed)
    if warm_start is not None:
        from toolkit.rl.checkpoint import with_architecture

        cfg = with_architecture(cfg, Path(warm_start))
    if configure is not None:
        cfg = configure(cfg)
    pool = None
    if cfg.n_workers > 1 and executor is not None:
        pool = plugins.load("executor", str(executor.name))(executor)
    path = Path(workdir) / CHECKPOINT
    extra = {} if extra is None else extra

    def timed(it: int, samples: int, stats: Any) -> Any:  # each iteration's wall-clock time, checkpointed
        out = on_iteration(it, samples, stats) if on_iteration is not None else None
        prev = np.asarray(extra.get(TIMES, np.zeros(0)), dtype=np.float64).ravel()
        extra[TIMES] = np.append(prev, time.time())
        return out

    t0 = time.perf_counter()
    try:
        result = ppo.train(env_fn, cfg, pool, path, resume=True, on_iteration=timed, extra=extra,
                           should_stop=should_stop, warm_start=warm_start)
    finally:
        if pool is not None:
            pool.close()
    return Trained(result=result, config=cfg, wall_s=time.perf_counter() - t0, checkpoint=path)


def adopted(path: Path, agent: Any, seed: int) -> Trained:
    """A slim policy (a shipped skill's, ``toolkit.rl.checkpoint.slim``) as a training that is over:
    its model, the samples and iterations it was trained with (its attributes), no per-iteration
    history, no time spent. Nothing resumes from it (a slim file has no training state)."""
    from toolkit.rl.checkpoint import load_attrs, load_policy, with_architecture
    from toolkit.rl.ppo import TrainResult

    attrs = load_attrs(path)
    result = TrainResult(model=load_policy(path), iterations=max(0, int(attrs.get("iteration", 0))),
                         samples=max(0, int(attrs.get("samples", 0))), history={}, extra={}, checkpoint_path=Path(path))
    return Trained(result=result, config=with_architecture(agent_config(agent, seed), path), wall_s=0.0,
                   checkpoint=Path(path))


def pick_frames(frames: list, n: int) -> list:
    """``n`` frames evenly spread over ``frames`` (first and last included)."""
    if not frames or n <= 0:
        return []
    idx = np.unique(np.linspace(0, len(frames) - 1, n).round().astype(int))
    return [frames[i] for i in idx]


TIMES = "iteration_time"
"""Key of the per-iteration wall-clock times in PPO's checkpointed ``extra``."""


def save_motion(workdir: Path, frames: list, n_filmstrip: int, fps: float = 30.0) -> list[str]:
    """``filmstrip.png`` (``n_filmstrip`` frames side by side) and ``motion.gif`` (all frames at
    ``fps``, enlarged to at least 320 px wide unless smoke-sized: ``toolkit.render.enlarge``) in
    ``workdir``; the names written."""
    import imageio.v3 as iio

    from toolkit.render import save_animation

    if not frames:
        return []
    strip = pick_frames(frames, n_filmstrip)
    iio.imwrite(Path(workdir) / "filmstrip.png",
                np.concatenate([np.asarray(f)[..., :3] for f in strip], axis=1).astype(np.uint8))
    save_animation(frames, Path(workdir) / "motion.gif", fps)
    return ["filmstrip.png", "motion.gif"]


def samples_axis(trained: Trained) -> list[int]:
    """Samples collected after each iteration ``(n_iterations,)``."""
    cfg = trained.config
    n_envs = cfg.n_workers * cfg.envs_per_worker
    per_it = n_envs * math.ceil(cfg.samples_per_iteration / n_envs)
    n_it = len(trained.result.history.get("mean_return", []))
    return [per_it * (i + 1) for i in range(n_it)]


def iteration_times(trained: Trained) -> list[float]:
    """Unix time at the end of each iteration ``(n_iterations,)`` (``extra`` of ``ppo.h5``; an
    older checkpoint without them: empty)."""
    return [float(t) for t in np.asarray(trained.result.extra.get(TIMES, np.zeros(0)), dtype=np.float64).ravel()]


def return_curve(trained: Trained) -> list[tuple]:
    """``[(samples, mean episode return, unix time)]`` per iteration, iterations with no episode
    left out (the time is missing for a checkpoint written before it was recorded)."""
    values = trained.result.history.get("mean_return", [])
    times = iteration_times(trained)
    rows = list(zip(samples_axis(trained), values, times if len(times) == len(values) else [None] * len(values)))
    return [(s, float(v), t) if t is not None else (s, float(v)) for s, v, t in rows if math.isfinite(v)]


def last_finite(values: list) -> float:
    """The last finite value of ``values`` (0.0 if none)."""
    finite = [float(v) for v in values if math.isfinite(float(v))]
    return finite[-1] if finite else 0.0
