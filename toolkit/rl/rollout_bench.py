"""``jt bench rollout``: where a policy task's environment spends its time, PPO's collection speed,
and what training really does per second, PPO updates included.

The task's own configuration (its SPD backend, its action space) unless the caller overrides it; an
action space that needs a trained prior (``action=pvae|cvae``) falls back to ``action=raw``
(``task_overrides``), so nothing is trained or looked up before the measurement. Three
measurements, in one run, on a task's own environment (``Task.make_env``):

* **the env alone**, random actions ``N(0, 0.3²)`` around the action space's centre: control
  steps per second at each control rate, and per 600 Hz substep the time in PyBullet's
  ``stepSimulation`` (physics), the SPD solve, state reads and torque writes (I/O), the NaN check
  and the episode's ``Watch`` (checks), and the rest of the env's Python per control step (env),
  from the simulator's ``timers``; the physics share is physics over the whole wall time; and
  every ``env.reset()`` timed apart from ``env.step()``: a reset's cost in control steps and spread
  over an episode's samples (``env_breakdown``);
* **PPO collection** with the paper's 1024-512 networks (``PPOConfig`` defaults): samples per
  second of ``n`` ``RolloutWorker`` s (16 envs each, one batched policy forward per step) in the
  ``local`` executor's process pool (one worker too: each in a process of its own, as training
  runs them), with each worker's peak resident memory;
* **training** as ``jt run`` runs it (``training``): the task's own agent preset and networks, from
  an untrained policy, in a temporary store, its per-iteration ``samples_per_s``, ``collect_s``
  and ``update_s`` read back from the evaluation's ``ppo.h5``; the first iteration (worker start,
  numba's cache) is left out of the figures when there are more.

The paper's figure to compare with: Yin et al. 2021 (``000`` §6.2) train one strategy (~1e8
samples) in "about six hours" on 48 cores: about 96 samples/s per core.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any, Callable, Optional, Sequence

import numpy as np

PAPER_SAMPLES_PER_CORE = 1.0e8 / (6 * 3600) / 48  #: 000 §6.2: ~1e8 samples, ~6 h, 48 cores
EPISODE_LENGTHS = (5, 600)  #: control steps per episode a reset's cost is spread over (reset_us_per_sample_L*)
UPDATE_SHARE_NOTE = 0.25  #: an update share above this is said in the table


def is_policy_task(cls: Any) -> bool:
    """A task whose evaluation trains PPO on an env of its own (``PolicyTask``: ``env_path`` and
    ``env_spec``), told without importing the tasks' package."""
    return bool(getattr(cls, "env_path", "")) and callable(getattr(cls, "env_spec", None))


def policy_tasks() -> list[str]:
    """The installed policy tasks' names, sorted (a broken plugin is left out)."""
    from toolkit import plugins
    from toolkit.errors import JtError

    out = []
    for name in plugins.names("task"):
        try:
            if is_policy_task(plugins.load("task", name)):
                out.append(name)
        except JtError:
            continue
    return out


def check_policy_task(name: str) -> None:
    """One ``JtError`` line for a task that is unknown or trains no policy, naming the policy tasks."""
    from toolkit import plugins
    from toolkit.errors import JtError, UnknownPlugin

    try:
        cls = plugins.load("task", name)
    except UnknownPlugin:
        cls = None
    if cls is None or not is_policy_task(cls):
        what = "unknown task" if cls is None else "task"
        why = "" if cls is None else " trains no policy"
        raise JtError(f"{what} '{name}'{why}; jt bench rollout takes a policy task: {', '.join(policy_tasks())}")


def task_overrides(task: str, action: str = "task", spd: str = "task",
                   extra: Sequence[str] = ()) -> tuple[list[str], str]:
    """The overrides the benchmark runs ``task`` with, and the header line that shows them.

    Args:
        task: a policy task.
        action: ``task`` (its own action space, unless that needs a trained prior: ``action=raw``
            then) or an action space to use.
        spd: ``task`` (its own backend) or a backend.
        extra: further overrides (e.g. ``sim.loop=python``), after these.

    Returns:
        ``(overrides, header)``; e.g. ``["action=raw", "sim.loop=auto"]`` and ``"task=getup
        action=raw (cvae needs a prior) sim.loop=auto (task's own: spd=df)"``.

    Raises:
        JtError: the config does not compose (one line).
    """
    from toolkit.config import compose, group_of

    extra = list(extra)
    over = ([] if action == "task" else [f"action={action}"]) + ([] if spd == "task" else [f"spd={spd}"]) + extra
    cfg = compose([f"task={task}", *over])
    own_action = str(group_of(group_of(cfg, "action") or {}, "name") or "")
    asked = action != "task" or any(o.startswith("action=") for o in extra)
    note = ""
    if not asked and own_action and _needs_prior(own_action):
        over.insert(0, "action=raw")
        note = f"({own_action} needs a prior)"
        cfg = compose([f"task={task}", *over])
    own = ([f"action={own_action}"] if not asked and not note and own_action else []) + \
        ([f"spd={group_of(group_of(cfg, 'spd') or {}, 'name')}"] if spd == "task" and
         not any(o.startswith("spd=") for o in extra) else [])
    words = [f"task={task}"] + [f"{o} {note}" if o == "action=raw" and note else o for o in over]
    header = " ".join(words) + (f" (task's own: {', '.join(own)})" if own else "")
    return over, header


def _needs_prior(action: str) -> bool:
    """The action space decodes through a trained prior (its ``needs_prior``): the benchmark then
    measures ``action=raw`` unless an action space is asked for."""
    from toolkit import plugins

    return bool(getattr(plugins.load("action", action), "needs_prior", False))


def _set_control_rate(env: Any, hz: float) -> bool:
    """Set the env's control rate if it has one the curriculum can set (the jumps)."""
    if hasattr(env, "control_hz") and hasattr(env, "substeps_now"):
        env.control_hz = float(hz)
        return True
    return False


def env_breakdown(make_env: Callable[[], Any], control_hz: float, control_steps: int = 400,
                  seed: int = 0) -> dict[str, float]:
    """Time ``control_steps`` random-action control steps of a fresh env at ``control_hz``.

    Every ``env.reset()`` (the first, and one after each episode's end) is timed apart from the
    ``env.step()`` calls (``perf_counter`` around each).

    Returns:
        ``control_steps_per_s`` (resets included, as before), ``substeps``, per-substep
        ``us_physics``, ``us_spd``, ``us_io``, ``us_checks``, ``us_env``, ``us_total`` (over the
        whole wall time, resets included), ``physics_share`` (physics / wall); and the resets:
        ``us_per_reset``, ``us_per_step`` (one control step, resets excluded), ``resets`` (count),
        ``reset_in_steps`` (``us_per_reset / us_per_step``), ``reset_share`` (of the wall time),
        ``reset_us_per_sample_L5`` and ``reset_us_per_sample_L600`` (a reset's cost spread over an
        episode of 5 / 600 control steps, µs per sample).
    """
    env = make_env()
    try:
        if not _set_control_rate(env, control_hz) and abs(env.sim.control_hz - control_hz) > 1e-9:
            return {}
        rng = np.random.default_rng(seed)
        low, high = env.action_space.low, env.action_space.high
        mid, half = 0.5 * (low + high), 0.5 * (high - low)

        def run(n: int) -> tuple[float, float, int]:
            """``(seconds in step, seconds in reset, resets)`` of ``n`` control steps."""
            clock = time.perf_counter
            t = clock()
            env.reset(seed=seed)
            reset_s, step_s, resets = clock() - t, 0.0, 1
            for _ in range(n):
                a = np.clip(mid + 0.3 * half * rng.standard_normal(mid.shape), low, high).astype(np.float32)
                t = clock()
                _, _, te, tr, _ = env.step(a)
                step_s += clock() - t
                if te or tr:
                    t = clock()
                    env.reset()
                    reset_s += clock() - t
                    resets += 1
            return step_s, reset_s, resets

        run(min(50, control_steps))  # warm up numba and the caches
        env.sim.reset_timers()
        t0 = time.perf_counter()
        step_s, reset_s, resets = run(control_steps)
        wall = time.perf_counter() - t0
        tm = env.sim.timers
        n = max(int(tm["substeps"]), 1)
        out = {"control_hz": float(control_hz), "control_steps_per_s": control_steps / wall,
               "substeps": float(n)}
        phys, spd, io, loop = (tm.get(k, 0.0) for k in ("physics_s", "spd_s", "io_s", "loop_s"))
        out.update(us_physics=phys / n * 1e6, us_spd=spd / n * 1e6, us_io=io / n * 1e6,
                   us_checks=max(loop - phys - spd - io, 0.0) / n * 1e6,
                   us_env=max(wall - loop, 0.0) / n * 1e6, us_total=wall / n * 1e6,
                   physics_share=phys / wall)
        out.update(_reset_figures(reset_s / resets * 1e6, step_s / control_steps * 1e6, float(resets)),
                   reset_share=reset_s / wall)
        return out
    finally:
        env.close()


def _reset_figures(us_per_reset: float, us_per_step: float, resets: float) -> dict[str, float]:
    """The reset figures of ``env_breakdown`` from a reset's and a control step's time (µs)."""
    out = {"us_per_reset": us_per_reset, "us_per_step": us_per_step, "resets": resets,
           "reset_in_steps": us_per_reset / us_per_step if us_per_step > 0 else float("nan")}
    out.update({f"reset_us_per_sample_L{n}": us_per_reset / n for n in EPISODE_LENGTHS})
    return out


def collection(env_fn: Callable[[int], Any], n_workers: int, envs_per_worker: int = 16,
               n_steps: int = 256, executor: Any = None, seed: int = 0) -> dict[str, float]:
    """PPO collection speed of ``n_workers`` rollout workers with the paper's networks.

    Returns:
        ``samples_per_s`` (all workers), ``samples_per_s_per_worker``, ``peak_rss_mb`` (the
        largest worker's peak resident memory).
    """
    from toolkit.rl.config import PPOConfig
    from toolkit.rl.networks import ActorCritic, output_scale_of
    from toolkit.rl.rollout import start_workers

    from toolkit.rl.rollout import RolloutWorker

    cfg = PPOConfig()
    if executor is not None:  # every worker in its own process, one worker too (as a pool runs them)
        args = [(env_fn, seed, list(range(w * envs_per_worker, (w + 1) * envs_per_worker)),
                 tuple(cfg.policy_hidden), tuple(cfg.value_hidden), cfg.normalize_actions, True)
                for w in range(n_workers)]
        workers = executor.actors(RolloutWorker, args)
    else:
        workers = start_workers(env_fn, seed, n_workers, envs_per_worker, cfg.policy_hidden, cfg.value_hidden,
                                cfg.normalize_actions, True, None)
    try:
        probe = env_fn(seed)
        obs_dim, act_dim = int(np.prod(probe.observation_space.shape)), int(np.prod(probe.action_space.shape))
        low, high = probe.action_space.low, probe.action_space.high
        scale = output_scale_of(probe)
        probe.close()
        model = ActorCritic(obs_dim, act_dim, cfg.policy_hidden, cfg.value_hidden, low, high, cfg.normalize_actions,
                            scale)
        workers.call("set_weights", [(model.numpy_state(),)] * workers.size)
        workers.call("collect", [(4, cfg.std_start, 0)] * workers.size)  # warm up
        t0 = time.perf_counter()
        workers.call("collect", [(n_steps, cfg.std_start, 1)] * workers.size)
        wall = time.perf_counter() - t0
        rss = workers.call("peak_rss_mb", [()] * workers.size)
    finally:
        workers.close()
    total = n_workers * envs_per_worker * n_steps
    return {"n_workers": float(n_workers), "samples_per_s": total / wall,
            "samples_per_s_per_worker": total / wall / n_workers, "peak_rss_mb": float(max(rss))}


def median_breakdown(make_env: Callable[[], Any], control_hz: float, control_steps: int = 400,
                     repeats: int = 3) -> dict[str, float]:
    """``env_breakdown`` ``repeats`` times, each on a fresh env: the median of every figure, and
    ``physics_shares`` ``[...]`` of the runs (a 2-core machine's speed drifts between runs; one
    run's share can be a few points off); ``reset_in_steps`` and the per-sample reset costs are
    those of the median reset and step times, so they agree with them."""
    rows = [env_breakdown(make_env, control_hz, control_steps) for _ in range(max(1, int(repeats)))]
    rows = [r for r in rows if r]
    if not rows:
        return {}
    out = {k: float(np.median([r[k] for r in rows])) for k in rows[0]}
    out.update(_reset_figures(out["us_per_reset"], out["us_per_step"], out["resets"]))  # consistent with the medians
    out["physics_shares"] = [float(r["physics_share"]) for r in rows]
    return out


def run_bench(task: str, overrides: list[str], rates: list[float], control_steps: int = 400,
              n_steps: int = 256, workers: tuple[int, ...] = (1, 2), echo: Optional[Callable] = None,
              repeats: int = 3, train_iterations: int = 0, train_workers: tuple[int, ...] = (1, 2),
              store_dir: Optional[Path | str] = None, header: Optional[str] = None) -> dict:
    """The whole benchmark for one task (see the module docstring); the env measurement is the
    median of ``repeats`` runs; ``echo`` prints progress. With ``train_iterations > 0``, training
    (``training``) with each of ``train_workers`` rollout workers, in ``store_dir`` (None: a
    temporary store, removed afterwards). ``header`` is the table's first line (default: the task
    and ``overrides``; ``task_overrides`` makes one)."""
    import shutil
    import tempfile

    from toolkit import plugins
    from toolkit.config import compose

    say = echo or (lambda s: None)
    cfg = compose([f"task={task}", *overrides])
    t = plugins.load("task", task)(cfg)
    result: dict[str, Any] = {"task": task, "overrides": overrides, "env": [], "collection": [], "training": [],
                              "header": header or f"task={task} {' '.join(overrides)}".rstrip()}
    for hz in rates:
        row = median_breakdown(lambda: t.make_env(seed=0), hz, control_steps, repeats)
        if row:
            result["env"].append(row)
            say(f"  env at {hz:g} Hz: {row['control_steps_per_s']:.0f} control steps/s, physics share "
                f"{100 * row['physics_share']:.0f} %, a reset {row['reset_in_steps']:.1f} control steps")
    env_fn = _EnvFn(task, overrides, t)
    for n in workers:  # rollout workers in the local executor's process pool
        executor = plugins.load("executor", "local")({"name": "local", "workers": n})
        try:
            row = collection(env_fn, n, n_steps=n_steps, executor=executor)
        finally:
            executor.close()
        result["collection"].append(row)
        say(f"  collection, {n} worker(s): {row['samples_per_s']:.0f} samples/s")
    col = {int(r["n_workers"]): r for r in result["collection"]}
    if 1 in col and 2 in col:
        result["speedup_2_workers"] = col[2]["samples_per_s"] / col[1]["samples_per_s"]
    if 1 in col:
        result["ratio_to_paper_per_core"] = col[1]["samples_per_s"] / PAPER_SAMPLES_PER_CORE
    if train_iterations > 0 and train_workers:
        tmp = None if store_dir is not None else tempfile.mkdtemp(prefix="jt-bench-rollout-")
        try:
            for n in train_workers:
                from toolkit.rl.train_bench import training

                row = training(task, overrides, n, train_iterations, store_dir if tmp is None else tmp, say)
                result["training"].append(row)
                say(f"  training, {n} worker(s): {row['train_samples_per_s']:.0f} samples/s, update "
                    f"{100 * row['update_share']:.0f} %")
        finally:
            if tmp is not None:
                shutil.rmtree(tmp, ignore_errors=True)
    return result


class _EnvFn:
    """Picklable ``env_fn(seed)`` for the rollout workers, built as training builds its own: a policy
    task's env spec is made once here and pickled to the workers with its env class (what
    ``toolkit.policy.train.EnvFactory`` does), so a worker's memory is what it is in a training
    run; any other task is composed in the worker (plugins through the registry)."""

    def __init__(self, task: str, overrides: list[str], built: Any = None) -> None:
        self.task, self.overrides = task, list(overrides)
        self._task: Any = None
        self._made: Optional[tuple[type, Any]] = None
        if built is not None and hasattr(built, "env_class") and hasattr(built, "env_spec"):
            self._made = (built.env_class, built.env_spec({}))

    def __call__(self, seed: int) -> Any:
        if self._made is not None:
            env_class, spec = self._made
            return env_class(spec, seed=seed)
        if self._task is None:
            from toolkit import plugins
            from toolkit.config import compose

            self._task = plugins.load("task", self.task)(compose([f"task={self.task}", *self.overrides]))
        return self._task.make_env(seed=seed)

    def __getstate__(self) -> dict:
        return {"task": self.task, "overrides": self.overrides, "_task": None, "_made": self._made}


def format_table(res: dict) -> str:
    """The benchmark as the text table ``jt bench rollout`` prints."""
    lines = [res.get("header") or f"task={res['task']} {' '.join(res['overrides'])}",
             f"{'control':>8} {'steps/s':>8} {'physics':>8} {'spd':>6} {'io':>6} {'checks':>7} {'env':>6} "
             f"{'total':>7}  physics share   (µs per 600 Hz substep)"]
    for r in res["env"]:
        lines.append(f"{r['control_hz']:>6.0f}Hz {r['control_steps_per_s']:>8.0f} {r['us_physics']:>8.1f} "
                     f"{r['us_spd']:>6.1f} {r['us_io']:>6.1f} {r['us_checks']:>7.1f} {r['us_env']:>6.1f} "
                     f"{r['us_total']:>7.1f}  {100 * r['physics_share']:>5.0f} %"
                     + (f" (median of {', '.join(f'{100 * x:.0f}' for x in r['physics_shares'])})"
                        if len(r.get("physics_shares", [])) > 1 else ""))
        if "us_per_reset" in r:
            lines.append(f"{'':>8} reset {r['us_per_reset']:.0f} µs = {r['reset_in_steps']:.1f} control steps of "
                         f"{r['us_per_step']:.0f} µs ({r['resets']:.0f} resets, {100 * r.get('reset_share', 0):.0f} % "
                         f"of the time); per sample over a 5 / 600-step episode: {r['reset_us_per_sample_L5']:.0f} / "
                         f"{r['reset_us_per_sample_L600']:.1f} µs")
    for r in res["collection"]:
        lines.append(f"PPO collection (1024-512 nets, 16 envs/worker), {int(r['n_workers'])} worker(s): "
                     f"{r['samples_per_s']:.0f} samples/s ({r['samples_per_s_per_worker']:.0f} per worker), "
                     f"peak RSS per worker {r['peak_rss_mb']:.0f} MB")
    if "speedup_2_workers" in res:
        lines.append(f"1 -> 2 workers: {res['speedup_2_workers']:.2f}x")
    if "ratio_to_paper_per_core" in res:
        lines.append(f"per core vs the paper's {PAPER_SAMPLES_PER_CORE:.0f} samples/s (000 §6.2: ~1e8 samples, "
                     f"6 h, 48 cores): {res['ratio_to_paper_per_core']:.2f}x")
    for r in res.get("training", []):
        nets = f"{'-'.join(map(str, r['policy_hidden']))} nets"
        n_it = int(r["iterations"])
        used = ("iteration 1 of 1, warm-up included" if r["warmup_included"] else
                "iteration 2 of 2" if n_it == 2 else f"iterations 2-{n_it} of {n_it}")
        lines.append(f"PPO training as jt run (agent={r['agent']}, {nets}, {int(r['samples_per_iteration'])} samples/"
                     f"iteration), {int(r['n_workers'])} worker(s): {r['train_samples_per_s']:.0f} samples/s with "
                     f"updates ({used}); collect {100 * r['collect_share']:.0f} %, update "
                     f"{100 * r['update_share']:.0f} %; wall {r['wall_s']:.0f} s (training {r['train_wall_s']:.0f} s)")
        if r["update_share"] > UPDATE_SHARE_NOTE:
            lines.append(f"  PPO update is {100 * r['update_share']:.0f} % of training wall time "
                         f"({int(r['n_workers'])} worker(s))")
    return "\n".join(lines)
