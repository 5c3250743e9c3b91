"""PPO as used by the athletic-jumping papers (000 §4.1, §6.2; 001 §3.4.1), in one readable file.

Read top to bottom: the exploration-noise and learning-rate schedules, GAE(λ)/TD(λ), the
clipped-surrogate update, and ``train`` (collect → estimate → update → checkpoint). Every
hyper-parameter, with its source, is in ``PPOConfig`` (``toolkit/rl/config.py``, torch-free,
re-exported here). Rollouts are collected by ``RolloutWorker``s (``toolkit/rl/rollout.py``), either
as executor actors or in this process; checkpoints (save, resume, warm start) are HDF5 files
(``toolkit/rl/checkpoint.py``).

Sources cited below: ``000`` = Yin et al. 2021 (the paper), ``001`` = Yang's thesis ch. 3 (the same
work), ``code`` = the authors' public code (arpspoof/Jump, ``presets/default/...``), consulted where
the paper is silent. See ``docs/ppo.md`` for the deviations and the sanity benchmark.
"""

from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np
import torch
from torch import nn

from toolkit.execution import stopping
from toolkit.rl import checkpoint as ckpt
from toolkit.rl.checkpoint import architecture_of, with_architecture
from toolkit.rl.config import PPOConfig, scheduled
from toolkit.rl.networks import ActorCritic, RunningObsStats, gaussian_log_prob
from toolkit.rl.rollout import merge_batches, start_workers, torch_threads

__all__ = ["IterationStats", "PPOConfig", "TrainResult", "action_std", "architecture_of", "compute_gae",
           "learning_rates", "ppo_update", "train", "with_architecture"]


class IterationStats(dict):
    """The scalar stats of one iteration (``{name: float}``), with per-episode lists kept as
    attributes so that ``items()`` yields only floats.

    Attributes:
        episodes: one dict per episode FINISHED in this iteration's batch: ``return``, ``length``,
            ``terminated`` and the numeric scalars of its last step's ``info``.
        starts: one dict per episode STARTED in this iteration's batch (its first observation
            ``s0`` is in the batch), ordered by step then environment: the numeric scalars of the
            ``info`` that ``env.reset`` returned (e.g. a start phase the task tags it with), then
            ``env`` (global environment index), ``step`` (row of the batch), ``value`` (V(s0) when
            collected) and ``target`` (the TD(λ) target of s0 computed by GAE in this iteration,
            in learning units, i.e. with ``reward_scale``). These four win over equally named
            ``info`` keys. What importance sampling of start states needs (spacetime bounds eqs
            11-12): a task can weight its start phases by ``target`` or ``target - value``.
        visits: one dict per batch row whose env reported its state (an env method
            ``visit_state()`` returning an array; none by default): ``state``, ``env``, ``step``,
            ``value`` and ``target`` as in ``starts`` (spacetime bounds eq 12's candidates).
        model: the learner's actor-critic after this iteration's update (read it, e.g. to evaluate
            the deterministic policy every N iterations; do not train it), or None.
    """

    def __init__(self, scalars: dict[str, float], episodes: list[dict[str, float]],
                 starts: Optional[list[dict[str, float]]] = None, visits: Optional[list[dict[str, Any]]] = None,
                 model: Any = None) -> None:
        super().__init__(scalars)
        self.episodes = episodes
        self.starts = [] if starts is None else starts
        self.visits = [] if visits is None else visits
        self.model = model


TIMING = ("samples_per_s", "collect_s", "update_s", "hook_s")
"""History keys that are wall-clock times (s) or rates: they differ between identical runs."""


@dataclasses.dataclass
class TrainResult:
    """What ``train`` returns.

    Attributes:
        model: the trained actor-critic (policy mean, value, observation normaliser).
        iterations: iterations done (including those before a resume).
        samples: samples collected.
        history: per-iteration scalar stats ``{name: [value per iteration]}``.
        extra: the caller's ``extra`` dict (restored from the checkpoint on resume).
        checkpoint_path: the last checkpoint written, if any.
        startup_s: wall time (s) of this call before its first collection: the probe env, the
            networks, a checkpoint or warm start read, the rollout workers started.
        checkpoint_s: wall time (s) this call spent writing checkpoints.
    """

    model: ActorCritic
    iterations: int
    samples: int
    history: dict[str, list[float]]
    extra: dict[str, Any]
    checkpoint_path: Optional[Path] = None
    startup_s: float = 0.0
    checkpoint_s: float = 0.0


def action_std(samples: float, cfg: PPOConfig) -> float:
    """σ after ``samples`` samples: linear from ``std_start`` to ``std_end`` (000 §4.1), or the
    step-wise ``std_schedule`` when one is given."""
    if cfg.std_schedule:
        step = scheduled(cfg.std_schedule, samples)
        return float(cfg.std_start if step is None else step[0])
    if cfg.std_anneal_samples <= 0:
        return float(cfg.std_end)
    frac = min(max(samples / cfg.std_anneal_samples, 0.0), 1.0)
    return float(cfg.std_start + frac * (cfg.std_end - cfg.std_start))


def learning_rates(samples: float, cfg: PPOConfig) -> tuple[float, float]:
    """``(policy_lr, value_lr)`` after ``samples`` samples: ``cfg``'s constants, or the step-wise
    ``lr_schedule`` when one is given."""
    step = scheduled(cfg.lr_schedule, samples) if cfg.lr_schedule else None
    return (float(cfg.policy_lr), float(cfg.value_lr)) if step is None else (step[0], step[1])


def compute_gae(
    rewards: np.ndarray,
    values: np.ndarray,
    next_values: np.ndarray,
    terminated: np.ndarray,
    truncated: np.ndarray,
    gamma: float,
    lam: float,
) -> tuple[np.ndarray, np.ndarray]:
    """GAE(λ) advantages and TD(λ) value targets (λ-returns), time-limit aware.

    ``δ_t = r_t + γ (1 - terminated_t) V'_t - V(s_t)``, ``A_t = δ_t + γλ (1 - done_t) A_{t+1}``,
    ``target_t = A_t + V(s_t)``, where ``V'_t`` is ``next_values[t]`` (the value of the state
    reached, the final observation's on a truncation) and ``done = terminated | truncated``. The
    last row is bootstrapped from ``next_values[-1]``.

    Args:
        rewards, values, next_values: ``(n_steps, n_envs)``.
        terminated, truncated: ``(n_steps, n_envs)`` bool.
        gamma: discount.
        lam: λ.

    Returns:
        ``(advantages, targets)``, both ``(n_steps, n_envs)`` float64.
    """
    not_term = 1.0 - np.asarray(terminated, dtype=np.float64)
    not_done = not_term * (1.0 - np.asarray(truncated, dtype=np.float64))
    values = np.asarray(values, dtype=np.float64)
    delta = rewards + gamma * not_term * np.asarray(next_values, dtype=np.float64) - values
    adv = np.zeros_like(delta)
    running = np.zeros(delta.shape[1:])
    for t in reversed(range(delta.shape[0])):
        running = delta[t] + gamma * lam * not_done[t] * running
        adv[t] = running
    return adv, adv + values


def _make_optimizer(params: Any, lr: float, cfg: PPOConfig) -> torch.optim.Optimizer:
    if cfg.optimizer == "sgd":
        return torch.optim.SGD(params, lr=lr, momentum=cfg.momentum, weight_decay=cfg.weight_decay)
    if cfg.optimizer == "adam":
        return torch.optim.Adam(params, lr=lr, weight_decay=cfg.weight_decay)
    raise ValueError(f"unknown optimizer {cfg.optimizer!r} (sgd or adam)")


def ppo_update(
    model: ActorCritic,
    pi_opt: torch.optim.Optimizer,
    v_opt: torch.optim.Optimizer,
    batch: dict[str, np.ndarray],
    std: float,
    cfg: PPOConfig,
    rng: np.random.Generator,
) -> dict[str, float]:
    """``cfg.epochs`` passes of clipped-surrogate policy and MSE value steps over a flat batch.

    Args:
        batch: ``obs`` ``(n, obs_dim)``, ``actions`` ``(n, act_dim)``, ``logp``, ``adv``,
            ``targets`` ``(n,)``.
        std: the σ the batch was collected with.
        rng: draws the minibatch permutations.

    Returns:
        Mean policy loss, value loss, clip fraction and approximate KL over all minibatches, and
        ``epochs_run`` (fewer than ``cfg.epochs`` when ``cfg.target_kl`` stopped the update).
    """
    obs = torch.as_tensor(batch["obs"], dtype=torch.float32)
    act = torch.as_tensor(batch["actions"], dtype=torch.float32)
    old_logp = torch.as_tensor(batch["logp"], dtype=torch.float32)
    adv = np.asarray(batch["adv"], dtype=np.float64)
    if cfg.norm_adv:
        adv = (adv - adv.mean()) / (adv.std() + 1e-5)
    if cfg.adv_clip > 0:
        adv = np.clip(adv, -cfg.adv_clip, cfg.adv_clip)
    adv_t = torch.as_tensor(adv, dtype=torch.float32)
    targets = torch.as_tensor(batch["targets"], dtype=torch.float32)
    n = obs.shape[0]
    sums = {"policy_loss": 0.0, "value_loss": 0.0, "clip_frac": 0.0, "approx_kl": 0.0}
    n_mb = 0
    epochs_run = 0
    for _ in range(cfg.epochs):
        epochs_run += 1
        kl_before, mb_before = sums["approx_kl"], n_mb
        perm = torch.from_numpy(rng.permutation(n))
        for start in range(0, n, cfg.minibatch_size):
            idx = perm[start:start + cfg.minibatch_size]
            x = model.norm(obs[idx])
            # policy: clipped surrogate (Schulman et al. 2017)
            logp = gaussian_log_prob(model.policy_mean(x), std, act[idx])
            log_ratio = logp - old_logp[idx]
            ratio = log_ratio.exp()
            a = adv_t[idx]
            surr = torch.min(ratio * a, ratio.clamp(1.0 - cfg.clip, 1.0 + cfg.clip) * a)
            pi_loss = -surr.mean()
            pi_opt.zero_grad()
            pi_loss.backward()
            if cfg.max_grad_norm > 0:
                nn.utils.clip_grad_norm_(model.pi.parameters(), cfg.max_grad_norm)
            pi_opt.step()
            # value: regression onto the TD(λ) targets
            v_loss = ((model.v(x).squeeze(-1) - targets[idx]) ** 2).mean()
            v_opt.zero_grad()
            v_loss.backward()
            if cfg.max_grad_norm > 0:
                nn.utils.clip_grad_norm_(model.v.parameters(), cfg.max_grad_norm)
            v_opt.step()
            with torch.no_grad():
                sums["policy_loss"] += float(pi_loss)
                sums["value_loss"] += float(v_loss)
                sums["clip_frac"] += float(((ratio - 1.0).abs() > cfg.clip).float().mean())
                sums["approx_kl"] += float(((ratio - 1.0) - log_ratio).mean())
            n_mb += 1
        epoch_kl = (sums["approx_kl"] - kl_before) / max(n_mb - mb_before, 1)
        if cfg.target_kl is not None and epoch_kl > cfg.target_kl:
            break
    out = {k: v / max(n_mb, 1) for k, v in sums.items()}
    out["epochs_run"] = float(epochs_run)
    return out


def _probe(env_fn: Callable[[int], Any], seed: int) -> tuple[int, int, np.ndarray, np.ndarray, Any]:
    import gymnasium

    from toolkit.rl.networks import output_scale_of

    env = env_fn(seed)
    try:
        space = env.action_space
        if not isinstance(space, gymnasium.spaces.Box):
            raise TypeError(f"PPO needs a continuous Box action space, got {space}")
        return (int(np.prod(env.observation_space.shape)), int(np.prod(space.shape)),
                np.asarray(space.low, np.float64).reshape(-1), np.asarray(space.high, np.float64).reshape(-1),
                output_scale_of(env))
    finally:
        env.close()


def train(
    env_fn: Callable[[int], Any],
    cfg: PPOConfig,
    executor: Any = None,
    checkpoint_path: str | Path | None = None,
    resume: bool = True,
    on_iteration: Optional[Callable[[int, int, IterationStats], Optional[dict[str, Any]]]] = None,
    extra: Optional[dict[str, Any]] = None,
    should_stop: Optional[Callable[[], bool]] = None,
    warm_start: str | Path | None = None,
) -> TrainResult:
    """Train a policy with PPO until ``cfg.total_samples`` samples have been collected.

    Args:
        env_fn: picklable ``env_fn(seed) -> gymnasium.Env`` (continuous Box actions).
        cfg: hyper-parameters (range-checked first: ``PPOConfig.check``).
        executor: a ``jt.executors`` plugin; its ``actors`` hold the rollout workers. None (or
            ``cfg.n_workers == 1``) runs them in this process, with identical results.
        checkpoint_path: HDF5 checkpoint written every ``cfg.checkpoint_every`` iterations and at
            the end.
        resume: continue from ``checkpoint_path`` if it exists.
        on_iteration: ``on_iteration(iteration, samples, stats)`` after each iteration (1-based
            count of iterations done, total samples). ``stats`` is an ``IterationStats``: a dict of
            floats (``mean_return``, ``mean_length``, ``n_episodes``, ``mean_reward``,
            ``policy_loss``, ``value_loss``, ``clip_frac``, ``approx_kl``, ``epochs_run``,
            ``explained_variance``, ``action_std``, [``policy_lr``, ``value_lr`` with an
            ``lr_schedule``], ``samples_per_s``, ``collect_s``, ``update_s``) whose ``.episodes``
            lists the episodes finished and ``.starts`` the episodes started in this iteration.
            It may return a dict of attributes to set (``env.set_wrapper_attr``) on every
            environment of every worker before the next iteration: a curriculum's bar height, or
            the reset-state distribution a task samples its episode starts from (e.g. start-phase
            weights computed from ``stats.starts``). They act from the environments' next
            ``reset``; they are checkpointed and re-applied on resume.
        extra: caller state saved in every checkpoint's ``extra`` group and, on resume, replaced in
            place by the saved one (e.g. a curriculum's state).
        should_stop: checked after every iteration; training ends early (with a final checkpoint)
            when it returns True, e.g. once a curriculum reaches ``z_freeze``.
        warm_start: a PPO checkpoint (e.g. a Stage-1 ``ppo.h5``) to start from when there is no
            checkpoint to resume (``checkpoint_path`` absent or missing, or ``resume=False``): the
            run is then a FRESH run (fresh optimisers, counters 0, the seeded RNGs of a fresh run,
            empty history, the caller's ``extra``) whose policy, value network and observation
            normaliser (with its running statistics) are ``warm_start``'s. Its network layout must
            be ``cfg``'s (build ``cfg`` with ``with_architecture(cfg, warm_start)``). Ignored when
            resuming: the checkpoint already holds the warm-started run.

    Returns:
        The trained model, counters, history and ``extra``.

    Raises:
        toolkit.errors.JtError: a bad ``cfg`` value, or a ``warm_start`` that is missing, not a
            PPO checkpoint, or of other observation/action sizes or network layout.
    """
    cfg.check()
    t_start = time.perf_counter()
    extra = {} if extra is None else extra
    obs_dim, act_dim, low, high, out_scale = _probe(env_fn, cfg.seed)
    torch.manual_seed(cfg.seed)
    model = ActorCritic(obs_dim, act_dim, cfg.policy_hidden, cfg.value_hidden, low, high,
                        cfg.normalize_actions, out_scale)
    pi_opt = _make_optimizer(model.pi.parameters(), cfg.policy_lr, cfg)
    v_opt = _make_optimizer(model.v.parameters(), cfg.value_lr, cfg)
    obs_stats = RunningObsStats(obs_dim, cfg.obs_norm_max_samples)
    rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([cfg.seed, 3])))
    iteration, samples = 0, 0
    history: dict[str, list[float]] = {}
    env_attrs: dict[str, Any] = {}
    path = Path(checkpoint_path) if checkpoint_path is not None else None
    started_from = str(warm_start) if warm_start is not None else None

    if path is not None and resume and path.exists():
        saved_run = ckpt.load_training(path, model, pi_opt, v_opt, obs_stats, rng)
        iteration, samples = saved_run["iteration"], saved_run["samples"]
        history, env_attrs = saved_run["history"], saved_run["env_attrs"]
        extra.clear()
        extra.update(saved_run["extra"])
        started_from = saved_run["warm_start"]
    elif warm_start is not None:  # a fresh run with another run's networks
        ckpt.load_warm_start(warm_start, cfg, model, obs_stats)

    n_envs = cfg.n_workers * cfg.envs_per_worker
    n_steps = math.ceil(cfg.samples_per_iteration / n_envs)
    workers = start_workers(env_fn, cfg.seed, cfg.n_workers, cfg.envs_per_worker,
                            cfg.policy_hidden, cfg.value_hidden, cfg.normalize_actions,
                            cfg.reset_each_iteration, executor)

    def save() -> Path:
        assert path is not None
        return ckpt.save_training(path, cfg, model, pi_opt, v_opt, obs_stats, rng, iteration, samples,
                                  history, env_attrs, extra, low, high, started_from)

    saved: Optional[Path] = None
    first = True
    saving = [0.0]  # s spent writing checkpoints

    def timed_save() -> Path:
        t = time.perf_counter()
        out = save()
        saving[0] += time.perf_counter() - t
        return out

    startup_s = time.perf_counter() - t_start
    try:
        if env_attrs:
            workers.call("set_env_attrs", [(env_attrs,)] * workers.size)
        while samples < cfg.total_samples:
            # 1. collect: every worker steps its envs n_steps times with the current weights,
            #    from new seeded episodes at run start and each checkpoint iteration (or always)
            t0 = time.perf_counter()
            std = action_std(samples, cfg)
            if cfg.lr_schedule:  # step-wise rates, written into the optimisers (resumes alike)
                lrs = learning_rates(samples, cfg)
                for opt, lr in zip((pi_opt, v_opt), lrs):
                    for group in opt.param_groups:
                        group["lr"] = lr
            restart = cfg.reset_each_iteration or first or iteration % cfg.checkpoint_every == 0
            first = False
            weights = model.numpy_state()
            workers.call("set_weights", [(weights,)] * workers.size)
            batch = merge_batches(workers.call("collect", [(n_steps, std, iteration, restart)] * workers.size))
            t1 = time.perf_counter()
            # 2. advantages GAE(λ) and value targets TD(λ)
            adv, targets = compute_gae(batch["rewards"] * cfg.reward_scale, batch["values"],
                                       batch["next_values"], batch["terminated"],
                                       batch["truncated"], cfg.gamma, cfg.lam)
            flat = {"obs": batch["obs"].reshape(-1, obs_dim),
                    "actions": batch["actions"].reshape(-1, act_dim),
                    "logp": batch["logp"].reshape(-1), "adv": adv.reshape(-1),
                    "targets": targets.reshape(-1)}
            # 3. update policy and value, then the observation normaliser (used from next batch)
            with torch_threads(cfg.update_threads):
                losses = ppo_update(model, pi_opt, v_opt, flat, std, cfg, rng)
            if cfg.obs_norm:
                obs_stats.update(flat["obs"])
                mean, sd = obs_stats.mean_std()
                model.norm.mean.copy_(torch.as_tensor(mean, dtype=torch.float32))
                model.norm.std.copy_(torch.as_tensor(sd, dtype=torch.float32))
            t2 = time.perf_counter()
            iteration += 1
            n_batch = flat["obs"].shape[0]
            samples += n_batch
            # 4. statistics, caller hook, checkpoint
            eps = batch["episodes"]
            starts = sorted(({**s, "value": float(batch["values"][s["step"], s["env"]]),
                              "target": float(targets[s["step"], s["env"]])} for s in batch["starts"]),
                            key=lambda s: (s["step"], s["env"]))
            resid = flat["targets"] - batch["values"].reshape(-1)
            var_t = float(np.var(flat["targets"]))
            stats: dict[str, float] = {
                "mean_return": float(np.mean([e["return"] for e in eps])) if eps else float("nan"),
                "mean_length": float(np.mean([e["length"] for e in eps])) if eps else float("nan"),
                "n_episodes": float(len(eps)),
                "mean_reward": float(batch["rewards"].mean()),
                **losses,
                "explained_variance": 1.0 - float(np.var(resid)) / var_t if var_t > 0 else float("nan"),
                "action_std": std,
                **({"policy_lr": lrs[0], "value_lr": lrs[1]} if cfg.lr_schedule else {}),
                "samples_per_s": n_batch / (t2 - t0),
                "collect_s": t1 - t0,
                "update_s": t2 - t1,
            }
            for k, v in stats.items():
                history.setdefault(k, []).append(float(v))
            t3 = time.perf_counter()
            if on_iteration is not None:
                visits = [{**v, "value": float(batch["values"][v["step"], v["env"]]),
                           "target": float(targets[v["step"], v["env"]])} for v in batch.get("visits", [])]
                attrs = on_iteration(iteration, samples, IterationStats(stats, eps, starts, visits, model))
                if attrs:
                    env_attrs.update(attrs)
                    workers.call("set_env_attrs", [(dict(attrs),)] * workers.size)
            history.setdefault("hook_s", []).append(time.perf_counter() - t3)  # the caller's hook (a curriculum's rollouts)
            if path is not None and iteration % cfg.checkpoint_every == 0:
                saved = timed_save()
            stopping.check()  # a safe point (SIGTERM): a resume repeats from the last checkpoint, bit for bit
            if should_stop is not None and should_stop():
                break
        if path is not None:
            saved = timed_save()
    finally:
        workers.close()
    return TrainResult(model, iteration, samples, history, extra, saved, startup_s, saving[0])
