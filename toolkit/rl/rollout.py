"""Rollout collection: workers that each own a few environments and a CPU copy of the policy.

``RolloutWorker`` is the object an executor actor holds (``executor.actors(RolloutWorker, args)``,
one actor per worker); with no executor the same workers run in this process. Every random number a
worker draws is derived from ``(seed, global env index, seed_offset)``, so a batch depends only on
the seeds and the weights, never on which process ran it or on timing.

Seeding, per environment ``k`` (global index ``worker * envs_per_worker + j``):

- construction: ``env_fn(derive_seed(seed, 0, k))``;
- action noise of a ``collect`` call: a fresh ``numpy`` PCG64 stream seeded by
  ``(seed, 1, k, seed_offset)`` (the trainer passes the iteration as ``seed_offset``);
- resets: a ``collect`` call that restarts (``reset=True``, or by default with
  ``reset_each_collect``, and always the first call) starts new episodes with
  ``env.reset(seed=derive_seed(seed, 2, k, seed_offset))``; otherwise episodes run on from the
  previous call. Episodes that end inside a call restart with ``env.reset()`` (the environment's
  own RNG, itself seeded by the last seeded reset). The trainer restarts at every iteration, or
  with ``reset_each_iteration=False`` at run start and after each checkpoint iteration, which is
  what makes a resumed run bit-identical to an uninterrupted one.
"""

from __future__ import annotations

import contextlib
import multiprocessing as mp
from typing import Any, Callable, Iterator, Optional, Sequence

import numpy as np
import torch

from toolkit.rl.networks import ActorCritic, output_scale_of, gaussian_log_prob


def derive_seed(*key: int) -> int:
    """A 32-bit seed derived from integers ``key`` (``numpy.random.SeedSequence``)."""
    return int(np.random.SeedSequence([int(k) for k in key]).generate_state(1)[0])


@contextlib.contextmanager
def single_thread() -> Iterator[None]:
    """Run torch on one thread inside the block (identical results in and out of workers)."""
    n = torch.get_num_threads()
    if n != 1:
        torch.set_num_threads(1)
    try:
        yield
    finally:
        if n != 1:
            torch.set_num_threads(n)


@contextlib.contextmanager
def torch_threads(n: int) -> Iterator[None]:
    """Run torch on ``n`` threads inside the block (0: leave torch's count as it is)."""
    before = torch.get_num_threads()
    if n and n != before:
        torch.set_num_threads(int(n))
    try:
        yield
    finally:
        if n and n != before:
            torch.set_num_threads(before)


def _scalars(info: dict[str, Any]) -> dict[str, float]:
    """The numeric scalar entries of a step ``info`` (keys starting with ``_`` skipped)."""
    out: dict[str, float] = {}
    for k, v in info.items():
        if str(k).startswith("_"):
            continue
        if isinstance(v, (bool, int, float, np.number)) or (isinstance(v, np.ndarray) and v.ndim == 0):
            out[str(k)] = float(v)
    return out


class RolloutWorker:
    """Owns ``envs_per_worker`` environments and a CPU copy of the actor-critic.

    Args:
        env_fn: picklable ``env_fn(seed) -> gymnasium.Env`` with a continuous ``Box`` action space.
        seed: the run seed.
        env_ids: global indices of this worker's environments.
        policy_hidden: policy MLP hidden sizes.
        value_hidden: value MLP hidden sizes.
        normalize_actions: see ``ActorCritic``.
        reset_each_collect: start new, seeded episodes at every ``collect`` call.
    """

    def __init__(
        self,
        env_fn: Callable[[int], Any],
        seed: int,
        env_ids: Sequence[int],
        policy_hidden: Sequence[int],
        value_hidden: Sequence[int],
        normalize_actions: bool = False,
        reset_each_collect: bool = True,
    ) -> None:
        if mp.parent_process() is not None:  # an actor process: the pool gives the parallelism
            torch.set_num_threads(1)
        self.seed = int(seed)
        self.env_ids = [int(k) for k in env_ids]
        self.envs = [env_fn(derive_seed(self.seed, 0, k)) for k in self.env_ids]
        space = self.envs[0].action_space
        obs_dim = int(np.prod(self.envs[0].observation_space.shape))
        with torch.random.fork_rng(devices=[]):  # initial weights are overwritten by set_weights
            self.model = ActorCritic(
                obs_dim, int(np.prod(space.shape)), policy_hidden, value_hidden,
                space.low, space.high, normalize_actions, output_scale_of(self.envs[0]),
            )
        self.model.eval()
        self.reset_each_collect = bool(reset_each_collect)
        self._obs: Optional[np.ndarray] = None  # (n_envs, obs_dim) current observations
        self._ep_ret = np.zeros(len(self.envs))
        self._ep_len = np.zeros(len(self.envs), dtype=np.int64)
        # reset-info scalars of each env's current episode until its first observation is batched
        self._pending_start: list[Optional[dict[str, float]]] = [None] * len(self.envs)
        # optional env.visit_state() -> array | None: the state of each batch row, for the learner
        self._visit = [getattr(getattr(env, "unwrapped", env), "visit_state", None) for env in self.envs]

    def set_weights(self, state: dict[str, np.ndarray]) -> None:
        """Load the learner's ``ActorCritic.numpy_state()``."""
        self.model.load_numpy_state(state)

    def set_env_attrs(self, attrs: dict[str, Any]) -> None:
        """Set attributes on every environment (``env.set_wrapper_attr``), e.g. curriculum values."""
        for env in self.envs:
            for k, v in attrs.items():
                env.set_wrapper_attr(k, v)

    def _reset_all(self, seed_offset: int) -> None:
        obs = []
        for j, (k, env) in enumerate(zip(self.env_ids, self.envs)):
            o, info = env.reset(seed=derive_seed(self.seed, 2, k, seed_offset))
            obs.append(np.asarray(o, dtype=np.float32).reshape(-1))
            self._pending_start[j] = _scalars(info)
        self._obs = np.stack(obs)
        self._ep_ret[:] = 0.0
        self._ep_len[:] = 0

    def collect(self, n_steps: int, std: float, seed_offset: int, reset: Optional[bool] = None) -> dict[str, Any]:
        """Run every environment ``n_steps`` control steps with actions ``N(mu(s), std^2)``.

        Args:
            n_steps: steps per environment.
            std: action standard deviation for this batch.
            seed_offset: mixes into every seed of this call (the trainer's iteration number).
            reset: start new seeded episodes first (True) or continue the running ones (False);
                None: as ``reset_each_collect``. The first call always starts new episodes.

        Returns:
            ``obs`` ``(n_steps, n_envs, obs_dim)`` float32, ``actions`` ``(n_steps, n_envs,
            act_dim)`` float32 (unbounded samples), ``logp``, ``values``, ``next_values``
            ``(n_steps, n_envs)`` float32, ``rewards`` ``(n_steps, n_envs)`` float64,
            ``terminated`` and ``truncated`` ``(n_steps, n_envs)`` bool, and ``episodes``: one dict
            per episode finished in this call (``return``, ``length``, ``terminated`` and the
            numeric scalars of the last step's ``info``), and ``starts``: one dict per episode whose
            first observation is in this batch (the numeric scalars of the ``info`` its
            ``env.reset`` returned, then ``env``: global env index, ``step``: its row ``t``), and
            ``visits``: for envs with a ``visit_state()`` method, one dict per row whose call
            returned an array (``state``, ``env``, ``step``), the state before that row's step.
            ``next_values[t]`` is the value of the
            state reached by step ``t``: for a time-limit truncation the value of the final
            observation (bootstrapping), for the last step of the call the value of the state the
            next call continues from; it is meaningless (multiplied by 0) where ``terminated``.
        """
        n_envs = len(self.envs)
        if (self.reset_each_collect if reset is None else reset) or self._obs is None:
            self._reset_all(seed_offset)
        assert self._obs is not None
        rngs = [np.random.Generator(np.random.PCG64(
            np.random.SeedSequence([self.seed, 1, k, int(seed_offset)]))) for k in self.env_ids]
        obs_dim, act_dim = self._obs.shape[1], self.model.act_dim
        out_obs = np.zeros((n_steps, n_envs, obs_dim), np.float32)
        out_act = np.zeros((n_steps, n_envs, act_dim), np.float32)
        out_logp = np.zeros((n_steps, n_envs), np.float32)
        out_val = np.zeros((n_steps + 1, n_envs), np.float32)
        out_next = np.zeros((n_steps, n_envs), np.float32)
        rewards = np.zeros((n_steps, n_envs), np.float64)
        term = np.zeros((n_steps, n_envs), bool)
        trunc = np.zeros((n_steps, n_envs), bool)
        final_obs: list[tuple[int, int, np.ndarray]] = []  # (t, env, obs) at truncations
        episodes: list[dict[str, float]] = []
        starts: list[dict[str, float]] = []
        visits: list[dict[str, Any]] = []
        with single_thread(), torch.no_grad():
            for t in range(n_steps):
                obs_t = torch.from_numpy(self._obs)
                mean, value = self.model(obs_t)
                eps = np.stack([r.standard_normal(act_dim) for r in rngs]).astype(np.float32)
                act = mean + float(std) * torch.from_numpy(eps)
                out_obs[t] = self._obs
                for j, info0 in enumerate(self._pending_start):
                    if info0 is not None:
                        starts.append({**info0, "env": self.env_ids[j], "step": t})
                        self._pending_start[j] = None
                out_act[t] = act.numpy()
                out_logp[t] = gaussian_log_prob(mean, float(std), act).numpy()
                out_val[t] = value.numpy()
                env_act = self.model.to_env(out_act[t])
                next_obs = np.empty_like(self._obs)
                for j, env in enumerate(self.envs):
                    state = self._visit[j]() if self._visit[j] is not None else None
                    if state is not None:
                        visits.append({"state": state, "env": self.env_ids[j], "step": t})
                    o, r, te, tr, info = env.step(env_act[j].astype(env.action_space.dtype))
                    o = np.asarray(o, dtype=np.float32).reshape(-1)
                    rewards[t, j], term[t, j], trunc[t, j] = float(r), bool(te), bool(tr and not te)
                    self._ep_ret[j] += float(r)
                    self._ep_len[j] += 1
                    if te or tr:
                        episodes.append({"return": float(self._ep_ret[j]),
                                         "length": float(self._ep_len[j]),
                                         "terminated": float(bool(te)), **_scalars(info)})
                        self._ep_ret[j], self._ep_len[j] = 0.0, 0
                        if trunc[t, j]:
                            final_obs.append((t, j, o))
                        o, info0 = env.reset()
                        o = np.asarray(o, dtype=np.float32).reshape(-1)
                        self._pending_start[j] = _scalars(info0)
                    next_obs[j] = o
                self._obs = next_obs
            out_val[n_steps] = self.model.value(torch.from_numpy(self._obs)).numpy()
            out_next[:] = out_val[1:]
            if final_obs:
                v_final = self.model.value(torch.from_numpy(np.stack([f[2] for f in final_obs])))
                for (t, j, _), v in zip(final_obs, v_final.numpy()):
                    out_next[t, j] = v
        out_next[term] = 0.0
        return {
            "obs": out_obs, "actions": out_act, "logp": out_logp, "values": out_val[:-1].copy(),
            "next_values": out_next, "rewards": rewards, "terminated": term, "truncated": trunc,
            "episodes": episodes, "starts": starts, "visits": visits,
        }

    def peak_rss_mb(self) -> float:
        """Peak resident memory of the process holding this worker (MB)."""
        import resource

        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0

    def close(self) -> None:
        """Close the environments."""
        for env in self.envs:
            env.close()
        self.envs = []


def start_workers(
    env_fn: Callable[[int], Any],
    seed: int,
    n_workers: int,
    envs_per_worker: int,
    policy_hidden: Sequence[int],
    value_hidden: Sequence[int],
    normalize_actions: bool,
    reset_each_collect: bool,
    executor: Any = None,
) -> Any:
    """Start ``n_workers`` ``RolloutWorker``s: as executor actors, or in-process without one.

    The worker layout (and so every seed) depends only on ``n_workers`` and ``envs_per_worker``,
    never on the executor: the same config gives the same batches in and out of process.
    """
    args = [
        (env_fn, seed, list(range(w * envs_per_worker, (w + 1) * envs_per_worker)),
         tuple(policy_hidden), tuple(value_hidden), normalize_actions, reset_each_collect)
        for w in range(n_workers)
    ]
    if executor is None or n_workers == 1:
        from toolkit.execution.actors import InlineActors

        return InlineActors(RolloutWorker, args)
    return executor.actors(RolloutWorker, args)


def merge_batches(parts: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Concatenate worker batches along the environment axis (axis 1, so column = global env
    index); list entries (``episodes``, ``starts``) are joined in worker order."""
    return {k: [e for p in parts for e in p[k]] if isinstance(parts[0][k], list)
            else np.concatenate([p[k] for p in parts], axis=1) for k in parts[0]}
