"""One run-up evaluation: PPO on ``RunupEnv`` to the sample budget, then the deterministic run-up.

``run_evaluation`` trains PPO (``toolkit.rl.ppo.train``, the ``agent`` group as the jump tasks read
it) checkpointing to ``workdir/ppo.h5`` (a killed evaluation resumes from it), then rolls the
deterministic policy out once from a fixed clip time (``eval_lead`` before the take-off foot's
mid-support, or a whole number of strides) and measures the take-off. Artifacts: ``ppo.h5``,
``rollout.h5`` (root, CoM and reference root per control step, per-step imitation reward, final
info), ``filmstrip.png`` and, when the run-up reached the take-off, ``takeoff_state.h5``
(``jt_tasks.runup.state_file``).
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any, Optional

import numpy as np

HISTORY_KEYS = ("r_goal", "r_imitation_mean", "took_off")  #: per-iteration means of finished episodes


def eval_start(env: Any, eval_lead: Optional[float]) -> float:
    """Clip time the deterministic rollout starts at.

    ``None``: the take-off foot's mid-support itself, so the run-up lasts exactly ``n_strides``
    cycles; else ``eval_lead`` seconds before it (the run-up lasts ``eval_lead`` plus
    ``n_strides - 1`` cycles).
    """
    return float(env.ref.t_mid - (0.0 if eval_lead is None else float(eval_lead)))


def rollout(env: Any, model: Any, t0: float, frames: int = 0, width: int = 160, height: int = 120) -> dict[str, Any]:
    """One deterministic run-up from clip time ``t0``; trajectories per control step and renders."""
    obs, _ = env.reset(seed=0, options={"time": t0})
    roots, coms, refs, times, imgs = [], [], [], [], []
    done, ret, info = False, 0.0, {}

    def record() -> None:
        q, _ = env.sim.state()
        roots.append(q[:7].copy())
        coms.append(env.links_and_com()[1])
        refs.append(env.ref.at(env.j0 + env.substeps_done).q[:7].copy())
        times.append(env.t)
        if frames > 0:
            imgs.append(env.render_frame(width, height))

    record()
    while not done:
        obs, r, te, tr, info = env.step(model.act(obs).astype(np.float32))
        ret += r
        done = te or tr
        record()
    if frames > 0:
        idx = np.unique(np.linspace(0, len(imgs) - 1, frames).round().astype(int))
        imgs = [imgs[i] for i in idx]
    q, qd = env.sim.state()
    return {"return": ret, "info": info, "root": np.array(roots), "com": np.array(coms), "ref_root": np.array(refs),
            "time": np.array(times), "frames": imgs, "q": q, "qd": qd,
            "imitation": np.array([t["imitation"] for t in env.terms_log])}


def run_evaluation(spec: Any, agent_cfg: Any, workdir: Path, seed: int, executor_cfg: Any = None,
                   eval_lead: Optional[float] = None, filmstrip_frames: int = 8,
                   filmstrip_size: tuple[int, int] = (160, 120), progress: Optional[Any] = None) -> dict[str, Any]:
    """Train, then measure; returns the train result, the rollout, history and timings.

    Args:
        spec: the ``RunupSpec``.
        agent_cfg: the ``agent`` group (``jt_tasks.jumping.train.ppo_config``).
        workdir: the evaluation's folder (checkpoint and artifacts).
        seed: the evaluation seed.
        executor_cfg: the ``executor`` group, for ``agent.n_workers > 1``.
        eval_lead: see ``eval_start``.
    """
    from toolkit import plugins
    from toolkit.rl import ppo
    from toolkit.rl.checkpoint import load_policy
    from toolkit.store import h5

    from jt_tasks.jumping.train import ppo_config, save_filmstrip
    from jt_tasks.runup.env import EnvFactory, RunupEnv
    from jt_tasks.takeoff.state_file import NAME, write_takeoff_state

    workdir = Path(workdir)
    cfg = ppo_config(agent_cfg, seed)
    extra: dict[str, Any] = {}

    def on_iteration(it: int, samples: int, stats: Any) -> None:
        eps = getattr(stats, "episodes", []) or []
        row = [float(samples)] + [float(np.mean([e.get(k, 0.0) for e in eps])) if eps else math.nan
                                  for k in HISTORY_KEYS]
        prev = np.asarray(extra.get("goal_history", np.zeros((0, 4))), dtype=np.float64).reshape(-1, 4)
        extra["goal_history"] = np.vstack([prev, [row]])
        if progress is not None:
            progress(min(samples / max(cfg.total_samples, 1), 1.0), f"r_goal {row[1]:.3f}")

    executor = None
    if cfg.n_workers > 1 and executor_cfg is not None:
        executor = plugins.load("executor", str(executor_cfg.name))(executor_cfg)
    t_start = time.perf_counter()
    try:
        result = ppo.train(EnvFactory(spec), cfg, executor, workdir / "ppo.h5", resume=True,
                           on_iteration=on_iteration, extra=extra)
    finally:
        if executor is not None:
            executor.close()
    wall = time.perf_counter() - t_start

    model = load_policy(workdir / "ppo.h5")
    env = RunupEnv(spec, seed=seed)
    try:
        ro = rollout(env, model, eval_start(env, eval_lead), filmstrip_frames, *filmstrip_size)
        targets, phase_time = dict(env.targets), float(env.ref.phase(env.clip_time) * env.ref.period)
    finally:
        env.close()
    info = ro["info"]
    save_filmstrip(workdir / "filmstrip.png", ro["frames"])
    h5.write(workdir / "rollout.h5",
             {"time": ro["time"], "root": ro["root"], "com": ro["com"], "ref_root": ro["ref_root"],
              "r_imitation": ro["imitation"],
              "info": {k: float(v) for k, v in info.items() if isinstance(v, (int, float))}},
             {"kind": spec.kind, "targets": str(targets), "return": float(ro["return"]),
              "reason": str(info.get("reason", ""))})
    if info.get("took_off"):
        achieved = {k[len("takeoff_"):]: float(v) for k, v in info.items() if k.startswith("takeoff_")}
        write_takeoff_state(workdir / NAME, ro["q"], ro["qd"], achieved, targets, spec.foot, spec.kind,
                            phase_time, float(info["r_goal"]))

    hist = result.history
    n_it = len(hist.get("mean_return", []))
    n_envs = cfg.n_workers * cfg.envs_per_worker
    per_it = n_envs * math.ceil(cfg.samples_per_iteration / n_envs)
    history: dict[str, list] = {"mean_return": [(per_it * (i + 1), float(v)) for i, v in
                                                enumerate(hist.get("mean_return", [])[:n_it]) if math.isfinite(v)]}
    goal_hist = np.asarray(result.extra.get("goal_history", np.zeros((0, 4))), dtype=np.float64).reshape(-1, 4)
    for col, key in enumerate(("goal_reward", "imitation_reward", "takeoff_rate"), start=1):
        history[key] = [(int(r[0]), float(r[col])) for r in goal_hist if math.isfinite(r[col])]
    sps = hist.get("samples_per_s", [])
    return {"result": result, "rollout": ro, "history": history, "wall_s": wall,
            "samples_per_s": float(np.mean(sps)) if sps else math.nan}
