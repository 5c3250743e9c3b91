"""Policy and value networks for PPO, the Gaussian log-density, and action-bound handling.

The policy is a Gaussian ``N(mu(s), sigma^2 I)`` whose mean is an MLP and whose standard deviation
``sigma`` is NOT a parameter: the trainer passes it in, annealed on a schedule (000 §4.1). The value
network has the same shape with one linear output unit (000 §4.1). Both read observations through
a shared, non-trainable observation normaliser (``(obs - mean) / std``, running statistics kept by
the trainer, as in the DeepMimic lineage and the authors' code).

Action bounds: actions are sampled *unbounded* from the Gaussian; the unbounded sample is what is
stored and scored (log-probabilities, PPO ratios). Only the copy sent to the environment is mapped
onto its ``Box``: by default (``normalize_actions=False``) the policy works in the environment's own
units and the action is clipped to ``[low, high]``; with ``normalize_actions=True`` the policy works
in ``[-1, 1]`` units, mapped affinely onto ``[low, high]`` and then clipped.

Output scale: an environment may declare ``policy_output_scale`` ``(act_dim,)``; the policy MLP's
output is multiplied by it before it is the Gaussian's mean, while ``sigma`` stays in the
environment's units (the authors' code of ``002`` scales the feedback network by each joint's
range ``a_std`` this way, so an SGD step moves the mean ~``a_std**2`` times further). None: 1.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np
import torch
from torch import nn

LOG_2PI = math.log(2.0 * math.pi)


def output_scale_of(env: "object") -> "np.ndarray | None":
    """An environment's ``policy_output_scale`` ``(act_dim,)`` (also through wrappers), or None."""
    scale = getattr(getattr(env, "unwrapped", env), "policy_output_scale", None)
    return None if scale is None else np.asarray(scale, dtype=np.float64).reshape(-1)


def mlp(in_dim: int, hidden: Sequence[int], out_dim: int, out_gain: float) -> nn.Sequential:
    """Fully connected ReLU network ``in_dim -> hidden... -> out_dim`` (linear output).

    Weights are orthogonally initialised (gain sqrt(2) for hidden layers, ``out_gain`` for the
    output layer), biases zero.
    """
    layers: list[nn.Module] = []
    d = in_dim
    for h in hidden:
        lin = nn.Linear(d, int(h))
        nn.init.orthogonal_(lin.weight, math.sqrt(2.0))
        nn.init.zeros_(lin.bias)
        layers += [lin, nn.ReLU()]
        d = int(h)
    out = nn.Linear(d, out_dim)
    nn.init.orthogonal_(out.weight, out_gain)
    nn.init.zeros_(out.bias)
    layers.append(out)
    return nn.Sequential(*layers)


def gaussian_log_prob(mean: torch.Tensor, std: float, actions: torch.Tensor) -> torch.Tensor:
    """Log-density of ``actions`` under ``N(mean, std^2 I)``, summed over action dimensions.

    Args:
        mean: ``(batch, act_dim)`` policy means.
        std: the scalar action standard deviation.
        actions: ``(batch, act_dim)`` unbounded (pre-clipping) actions.

    Returns:
        ``(batch,)`` log-probabilities.
    """
    z = (actions - mean) / std
    d = mean.shape[-1]
    return -0.5 * (z * z).sum(-1) - d * (math.log(std) + 0.5 * LOG_2PI)


class ObsNormalizer(nn.Module):
    """Non-trainable ``(obs - mean) / std`` with the statistics held in buffers.

    Args:
        obs_dim: observation size.
    """

    def __init__(self, obs_dim: int) -> None:
        super().__init__()
        self.register_buffer("mean", torch.zeros(obs_dim))
        self.register_buffer("std", torch.ones(obs_dim))

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        return (obs - self.mean) / self.std


class RunningObsStats:
    """Running mean/std of observations (float64 sums), frozen after ``max_count`` samples.

    Following the authors' normaliser, statistics are accumulated over every collected observation
    until ``max_count`` samples have been seen, then frozen; ``std = sqrt(var) + eps``.

    Args:
        obs_dim: observation size.
        max_count: samples after which the statistics stop changing.
        eps: added to the standard deviation (guards constant features).
    """

    def __init__(self, obs_dim: int, max_count: int = 1_000_000, eps: float = 0.01) -> None:
        self.count = 0
        self.sum = np.zeros(obs_dim)
        self.sumsq = np.zeros(obs_dim)
        self.max_count = int(max_count)
        self.eps = float(eps)

    def update(self, obs: np.ndarray) -> None:
        """Accumulate ``obs`` ``(n, obs_dim)`` unless frozen."""
        if self.count >= self.max_count or len(obs) == 0:
            return
        x = np.asarray(obs, dtype=np.float64).reshape(-1, self.sum.shape[0])
        self.count += x.shape[0]
        self.sum += x.sum(0)
        self.sumsq += (x * x).sum(0)

    def mean_std(self) -> tuple[np.ndarray, np.ndarray]:
        """Current ``(mean, std)`` ``(obs_dim,)`` each; identity before any data."""
        if self.count == 0:
            return np.zeros_like(self.sum), np.ones_like(self.sum)
        mean = self.sum / self.count
        var = np.maximum(self.sumsq / self.count - mean * mean, 0.0)
        return mean, np.sqrt(var) + self.eps

    def state(self) -> dict[str, np.ndarray]:
        """Arrays for a checkpoint."""
        return {"count": np.asarray(self.count), "sum": self.sum.copy(), "sumsq": self.sumsq.copy()}

    def load_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore ``state()``."""
        self.count = int(np.asarray(state["count"]))
        self.sum = np.array(state["sum"], dtype=np.float64)
        self.sumsq = np.array(state["sumsq"], dtype=np.float64)


class ActorCritic(nn.Module):
    """Gaussian policy mean ``pi`` and value ``v``, both behind the observation normaliser.

    Args:
        obs_dim: observation size.
        act_dim: action size.
        policy_hidden: hidden layer sizes of the policy MLP.
        value_hidden: hidden layer sizes of the value MLP.
        low: ``(act_dim,)`` lower bounds of the environment's Box.
        high: ``(act_dim,)`` upper bounds.
        normalize_actions: policy works in ``[-1, 1]`` units mapped onto ``[low, high]``.
        out_scale: ``(act_dim,)`` factors on the policy MLP's output (module docstring); None: 1.
    """

    def __init__(
        self,
        obs_dim: int,
        act_dim: int,
        policy_hidden: Sequence[int],
        value_hidden: Sequence[int],
        low: np.ndarray,
        high: np.ndarray,
        normalize_actions: bool = False,
        out_scale: "np.ndarray | None" = None,
    ) -> None:
        super().__init__()
        self.obs_dim, self.act_dim = int(obs_dim), int(act_dim)
        self.norm = ObsNormalizer(obs_dim)
        self.pi = mlp(obs_dim, policy_hidden, act_dim, out_gain=0.01)
        self.v = mlp(obs_dim, value_hidden, 1, out_gain=1.0)
        self.low = np.asarray(low, dtype=np.float64).reshape(act_dim)
        self.high = np.asarray(high, dtype=np.float64).reshape(act_dim)
        self.normalize_actions = bool(normalize_actions)
        self.out_scale = None if out_scale is None else np.asarray(out_scale, dtype=np.float64).reshape(act_dim)
        self._scale = None if out_scale is None else torch.as_tensor(self.out_scale, dtype=torch.float32)

    def policy_mean(self, x: torch.Tensor) -> torch.Tensor:
        """Policy means ``(batch, act_dim)`` for *normalised* observations ``x``: the MLP's output
        times ``out_scale`` (what the learner's log-densities must use, as the workers do)."""
        mu = self.pi(x)
        return mu if self._scale is None else mu * self._scale

    def forward(self, obs: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Policy means ``(batch, act_dim)`` and values ``(batch,)`` for raw ``obs``."""
        x = self.norm(obs)
        return self.policy_mean(x), self.v(x).squeeze(-1)

    def mean_action(self, obs: torch.Tensor) -> torch.Tensor:
        """Policy means ``(batch, act_dim)`` (the deterministic action, before bounds)."""
        return self.policy_mean(self.norm(obs))

    def value(self, obs: torch.Tensor) -> torch.Tensor:
        """State values ``(batch,)``."""
        return self.v(self.norm(obs)).squeeze(-1)

    def to_env(self, actions: np.ndarray) -> np.ndarray:
        """Map unbounded policy actions ``(..., act_dim)`` onto the environment's Box."""
        a = np.asarray(actions, dtype=np.float64)
        if self.normalize_actions:
            a = 0.5 * (self.low + self.high) + 0.5 * (self.high - self.low) * a
        return np.clip(a, self.low, self.high)

    def act(self, obs: np.ndarray) -> np.ndarray:
        """Deterministic environment action ``(act_dim,)`` for one observation ``(obs_dim,)``."""
        with torch.no_grad():
            mu = self.mean_action(torch.as_tensor(obs, dtype=torch.float32).reshape(1, -1))
        return self.to_env(mu.numpy()[0])

    def numpy_state(self) -> dict[str, np.ndarray]:
        """``state_dict()`` as numpy arrays (copies): what rollout workers receive."""
        return {k: v.detach().cpu().numpy().copy() for k, v in self.state_dict().items()}

    def load_numpy_state(self, state: dict[str, np.ndarray]) -> None:
        """Load a ``numpy_state()``."""
        self.load_state_dict({k: torch.from_numpy(np.asarray(v)) for k, v in state.items()})
