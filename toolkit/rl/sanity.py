"""Sanity benchmark: PPO learns a small standard control task (gymnasium ``Pendulum-v1``).

The paper's settings (clip 0.02, policy lr 2.5e-5, 1024-512 nets, γ = 1) are tuned for 1e8-sample
humanoid jumping with sparse rewards; on a 200-step dense-reward task with a 2e5-sample budget they
barely move the policy. ``sanity_config`` therefore uses the usual small-task PPO settings (see
docs/ppo.md for the measured curve). Only the hyper-parameters differ: the code path is the one
jt's tasks train with.

Run::

    PYTHONPATH=.:plugins python -m toolkit.rl.sanity                # learning curve, 1 process
    PYTHONPATH=.:plugins python -m toolkit.rl.sanity --bench        # samples/s, 1 vs 2 workers
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from typing import Any, Optional

import numpy as np
import torch

from toolkit.rl.ppo import PPOConfig, train


@dataclasses.dataclass(frozen=True)
class GymEnvFn:
    """Picklable ``env_fn(seed)`` for a registered gymnasium id (the seed is unused: resets are
    seeded by the rollout worker)."""

    env_id: str
    max_episode_steps: Optional[int] = None

    def __call__(self, seed: int) -> Any:
        import gymnasium

        if self.max_episode_steps is None:
            return gymnasium.make(self.env_id)
        return gymnasium.make(self.env_id, max_episode_steps=self.max_episode_steps)


def sanity_config(total_samples: int = 200_000, seed: int = 0, n_workers: int = 2) -> PPOConfig:
    """Small-task PPO settings for Pendulum-v1 (200-step episodes, torques in [-2, 2]).

    8 environments × 200 steps = 1600 samples per iteration: every iteration is exactly one full
    episode per environment, so resetting at each iteration cuts nothing.
    """
    return PPOConfig(
        policy_hidden=(64, 64),
        value_hidden=(64, 64),
        std_start=0.5,  # in [-1, 1] action units (normalize_actions), i.e. 1 N·m
        std_end=0.1,
        std_anneal_samples=100_000,
        samples_per_iteration=1600,
        epochs=10,
        minibatch_size=64,
        clip=0.2,
        policy_lr=3e-4,
        value_lr=1e-3,
        optimizer="adam",
        weight_decay=0.0,
        max_grad_norm=0.5,
        gamma=0.95,
        lam=0.95,
        normalize_actions=True,
        reward_scale=0.1,
        total_samples=total_samples,
        checkpoint_every=10**9,
        seed=seed,
        n_workers=n_workers,
        envs_per_worker=8 // n_workers,
    )


def run_sanity(
    env_id: str = "Pendulum-v1",
    total_samples: int = 200_000,
    seed: int = 0,
    n_workers: int = 2,
    executor: Any = None,
    cfg: Optional[PPOConfig] = None,
    verbose: bool = False,
) -> dict[str, Any]:
    """Train on ``env_id`` and report the learning curve.

    Args:
        env_id: gymnasium id with a Box action space.
        total_samples: budget.
        seed: run seed.
        n_workers: rollout workers (the seed layout; 8 environments in all).
        executor: optional executor holding the workers (None: in this process).
        cfg: override the whole config.
        verbose: print one line per iteration.

    Returns:
        ``final_return`` (mean episode return over the last 5 iterations), ``best_return``,
        ``curve`` ``[(samples, mean_return), ...]``, ``seconds``, ``samples``.
    """
    cfg = cfg or sanity_config(total_samples, seed, n_workers)
    curve: list[tuple[int, float]] = []

    def log(it: int, samples: int, stats: dict[str, Any]) -> None:
        curve.append((samples, stats["mean_return"]))
        if verbose:
            print(f"it {it:4d} samples {samples:7d} return {stats['mean_return']:9.1f} "
                  f"std {stats['action_std']:.3f} vloss {stats['value_loss']:.3f} "
                  f"kl {stats['approx_kl']:.4f} sps {stats['samples_per_s']:.0f}", flush=True)

    t0 = time.perf_counter()
    res = train(GymEnvFn(env_id), cfg, executor=executor, on_iteration=log)
    seconds = time.perf_counter() - t0
    returns = [r for _, r in curve]
    return {
        "env_id": env_id, "seed": seed, "samples": res.samples, "seconds": seconds,
        "final_return": float(np.nanmean(returns[-5:])), "best_return": float(np.nanmax(returns)),
        "curve": curve,
    }


def bench_workers(
    workers: tuple[int, ...] = (1, 2), iterations: int = 8, env_id: str = "Pendulum-v1"
) -> dict[int, dict[str, float]]:
    """Samples/s with the local executor at each worker count (8 envs in all, sanity settings).

    Returns:
        ``{n_workers: {"samples_per_s": total, "collect_samples_per_s": collection only}}``,
        measured over the iterations after the first (which includes worker start-up).
    """
    from omegaconf import OmegaConf

    from toolkit import plugins

    local = plugins.load("executor", "local")  # through the registry: toolkit never imports a plugin
    out: dict[int, dict[str, float]] = {}
    for n in workers:
        cfg = sanity_config(iterations * 1600, 0, n)
        stats: list[dict[str, float]] = []
        with local(OmegaConf.create({"name": "local", "workers": n, "start_method": "spawn"})) as ex:
            train(GymEnvFn(env_id), cfg, executor=ex,
                  on_iteration=lambda i, s, st: stats.append(st))
        steady = stats[1:]
        n_samples = 1600 * len(steady)
        out[n] = {
            "samples_per_s": n_samples / sum(s["collect_s"] + s["update_s"] for s in steady),
            "collect_samples_per_s": n_samples / sum(s["collect_s"] for s in steady),
        }
    return out


def main(argv: Optional[list[str]] = None) -> None:
    """Command line: sanity run (default) or ``--bench``."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--env", default="Pendulum-v1")
    p.add_argument("--samples", type=int, default=200_000)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--threads", type=int, default=1, help="torch threads of the learner")
    p.add_argument("--bench", action="store_true", help="samples/s with 1 vs 2 workers")
    a = p.parse_args(argv)
    torch.set_num_threads(a.threads)
    if a.bench:
        print(json.dumps(bench_workers(env_id=a.env), indent=1))
        return
    r = run_sanity(a.env, a.samples, a.seed, verbose=True)
    print(json.dumps({k: v for k, v in r.items() if k != "curve"}, indent=1))


if __name__ == "__main__":
    main()
