"""One strategy evaluation (``000`` Alg. 1 line 9): PPO with a curriculum, then the deterministic jump.

``run_evaluation`` trains PPO (``toolkit.rl.ppo.train``) on ``JumpEnv``s until the curriculum is
frozen (``z_freeze``, ``000`` §6.1.4) or the sample budget is spent, checkpointing to
``workdir/ppo.h5`` (a killed evaluation resumes from it), then rolls the deterministic policy out
once at the reached difficulty and measures the strategy feature. Artifacts: ``ppo.h5`` (the
policy, with optimiser and curriculum state), ``filmstrip.png`` (the final jump), ``rollout.h5``
(root trajectory, CoM, features, take-off features).
"""

from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path
from typing import Any, Optional

import numpy as np


def ppo_config(agent: Any, seed: int) -> Any:
    """``PPOConfig`` from the ``agent`` group (None: the paper's defaults) and the evaluation seed."""
    from toolkit.interfaces.plugin import Plugin
    from toolkit.rl.ppo import PPOConfig

    params = Plugin.params_of(agent) if agent is not None else {}
    known = {f.name for f in dataclasses.fields(PPOConfig)}
    unknown = sorted(set(params) - known)
    if unknown:
        from toolkit.errors import JtError

        raise JtError(f"agent: unknown key(s) {', '.join(unknown)} (valid keys: {', '.join(sorted(known))})")
    for k in ("policy_hidden", "value_hidden"):
        if k in params:
            params[k] = tuple(int(v) for v in params[k])
    params["seed"] = int(seed)
    return PPOConfig(**params)


def rollout(env: Any, model: Any, frames: int = 0, width: int = 160, height: int = 120) -> dict[str, Any]:
    """One deterministic episode; root/CoM trajectory per control step and ``frames`` renders."""
    obs, _ = env.reset(seed=0)
    roots, coms, times, imgs = [], [], [], []
    done, ret, info = False, 0.0, {}
    renders = frames > 0

    def record() -> None:
        q, _ = env.sim.state()
        roots.append(q[:7].copy())
        coms.append(env._com_and_links()[0])
        times.append(env.t)
        if renders:
            imgs.append(env.render_frame(width, height))

    while not done:
        record()
        obs, r, te, tr, info = env.step(model.act(obs).astype(np.float32))
        ret += r
        done = te or tr
    record()
    if renders:
        idx = np.unique(np.linspace(0, len(imgs) - 1, frames).round().astype(int))
        imgs = [imgs[i] for i in idx]
    return {"return": ret, "info": info, "root": np.array(roots), "com": np.array(coms),
            "time": np.array(times), "frames": imgs,
            "feature_quat": env.tracker.stage2(env.suite.rotation()),
            "feature_angle": env.tracker.stage1()}


def save_filmstrip(path: Path, frames: list) -> None:
    """Frames side by side as one PNG."""
    import imageio.v3 as iio

    if frames:
        iio.imwrite(path, np.concatenate([np.asarray(f)[..., :3] for f in frames], axis=1).astype(np.uint8))


def run_evaluation(spec: Any, cur: Any, agent_cfg: Any, workdir: Path, seed: int,
                   executor_cfg: Any = None, filmstrip_frames: int = 8, filmstrip_size: tuple[int, int] = (160, 120),
                   progress: Optional[Any] = None, warm_start: Optional[Path] = None) -> dict[str, Any]:
    """Train, then measure; returns metrics, history and the deterministic rollout.

    Args:
        spec: the ``EnvSpec``.
        cur: the curriculum (an ``IterationCurriculum``: ``bind``, ``on_iteration``, ``frozen``).
        agent_cfg: the ``agent`` group.
        workdir: the evaluation's folder (checkpoint and artifacts).
        seed: the evaluation seed.
        executor_cfg: the ``executor`` group, for ``agent.n_workers > 1``.
        warm_start: Stage 2: a Stage-1 ``ppo.h5`` to start from (``jt_tasks.jumping.stage2``).
    """
    from toolkit import plugins
    from toolkit.rl import ppo
    from toolkit.rl.checkpoint import load_policy
    from toolkit.store import h5

    from jt_tasks.jumping.env import EnvFactory, JumpEnv

    cfg = ppo_config(agent_cfg, seed)
    extra = cur.bind({})
    attrs0 = cur.env_attrs()
    spec = dataclasses.replace(spec, control_hz=float(attrs0.get("control_hz", spec.control_hz)))
    z_attr = next((k for k in attrs0 if k in ("bar_height", "obstacle_width")), "bar_height")
    z_hist: list[tuple[float, float, float]] = []  # (samples, z, success rate) per iteration

    def on_iteration(it: int, samples: int, stats: Any) -> dict[str, Any]:
        if not z_hist and extra.get("z_history") is not None:  # resumed: continue the saved curve
            z_hist.extend(tuple(float(x) for x in row) for row in np.asarray(extra["z_history"]).reshape(-1, 3))
        out = cur.on_iteration(it, samples, stats)
        eps = getattr(stats, "episodes", []) or []
        rate = float(np.mean([e.get("success", 0.0) for e in eps])) if eps else math.nan
        z_hist.append((float(samples), float(out.get(z_attr, math.nan)), rate))
        extra["z_history"] = np.asarray(z_hist, dtype=np.float64)
        nov = [float(e["r_novelty"]) for e in eps if "r_novelty" in e]
        if nov:  # Stage 2: mean r_novelty (000 eq 12) of the iteration's episodes
            prev = np.asarray(extra.get("novelty_history", np.zeros((0, 2))), dtype=np.float64).reshape(-1, 2)
            extra["novelty_history"] = np.vstack([prev, [[float(samples), float(np.mean(nov))]]])
        if progress is not None:
            progress(min(samples / max(cfg.total_samples, 1), 1.0), f"{z_attr} {out.get(z_attr)}")
        return out

    path = Path(workdir) / "ppo.h5"
    if warm_start is not None:  # Stage 2 (000 §7.1.1): start from the Stage-1 policy
        from jt_tasks.jumping.stage2 import adopt_architecture, write_warm_start

        cfg = adopt_architecture(cfg, Path(warm_start))
        if not path.exists():
            write_warm_start(path, Path(warm_start), cfg, EnvFactory(spec), extra)
    executor = None
    if cfg.n_workers > 1 and executor_cfg is not None:
        executor = plugins.load("executor", str(executor_cfg.name))(executor_cfg)
    t0 = time.perf_counter()
    try:
        result = ppo.train(EnvFactory(spec), cfg, executor, path, resume=True,
                           on_iteration=on_iteration, extra=extra, should_stop=cur.frozen)
    finally:
        if executor is not None:
            executor.close()
    wall = time.perf_counter() - t0
    saved = result.extra.get("z_history")
    if saved is not None and len(np.asarray(saved)) >= len(z_hist):
        z_hist = [tuple(float(x) for x in row) for row in np.asarray(saved).reshape(-1, 3)]
    if result.extra.get(cur.extra_key):
        cur.load_state(dict(result.extra[cur.extra_key]))
    # deterministic jump at the reached difficulty
    model = load_policy(path)
    env = JumpEnv(spec, seed=seed)
    try:
        for k, v in cur.env_attrs().items():
            setattr(env, k, v)
        ro = rollout(env, model, filmstrip_frames, *filmstrip_size)
    finally:
        env.close()
    save_filmstrip(Path(workdir) / "filmstrip.png", ro["frames"])
    h5.write(Path(workdir) / "rollout.h5",
             {"time": ro["time"], "root": ro["root"], "com": ro["com"],
              "feature_quat": np.asarray(ro["feature_quat"], dtype=float),
              "feature_angle": np.array([ro["feature_angle"]])},
             {"features": {k: float(v) for k, v in spec.features.items()}, "kind": spec.kind,
              "return": float(ro["return"]), "reason": str(ro["info"].get("reason", ""))})
    hist = result.history
    n_it = len(hist.get("mean_return", []))
    per_it = cfg.n_workers * cfg.envs_per_worker * math.ceil(cfg.samples_per_iteration / (cfg.n_workers * cfg.envs_per_worker))
    samples_axis = [per_it * (i + 1) for i in range(n_it)]
    history = {"mean_return": [(s, float(v)) for s, v in zip(samples_axis, hist.get("mean_return", []))
                               if math.isfinite(v)],
               z_attr: [(int(s), z) for s, z, _ in z_hist],
               "success_rate": [(int(s), r) for s, _, r in z_hist if math.isfinite(r)]}
    nov_hist = np.asarray(result.extra.get("novelty_history", np.zeros((0, 2))), dtype=np.float64).reshape(-1, 2)
    if len(nov_hist):
        history["novelty"] = [(int(s), float(v)) for s, v in nov_hist]
    succ = [r for _, _, r in z_hist if math.isfinite(r)]
    sps = hist.get("samples_per_s", [])
    return {"result": result, "rollout": ro, "history": history, "wall_s": wall, "succ": succ,
            "samples_per_s": float(np.mean(sps)) if sps else math.nan, "z": cur.z}
