"""``PPOConfig``: every PPO hyper-parameter with its source, and its range check.

This module imports only the standard library (no torch, no numpy), so the config layer can build
and check the ``agent`` group at composition time without loading the training stack.

Sources cited below: ``000`` = Yin et al. 2021 (the athletic-jumping paper), ``001`` = Yang's
thesis ch. 3 (the same work), ``code`` = the authors' public code (arpspoof/Jump,
``presets/default/...``), consulted where the paper is silent, ``getup`` = the get-up paper §5.6
(step-wise std and learning-rate schedules). See ``docs/ppo.md`` for the deviations.
"""

from __future__ import annotations

import dataclasses
import json
import math
import numbers
from typing import Any, Optional, Sequence

OPTIMIZERS = ("sgd", "adam")  #: the ``optimizer`` values ``train`` knows


@dataclasses.dataclass
class PPOConfig:
    """Every PPO hyper-parameter; defaults are the jumping papers' values."""

    policy_hidden: tuple[int, ...] = (1024, 512)
    """Policy MLP hidden sizes, ReLU (000 §4.1 "two hidden layers with 1024 and 512 units")."""
    value_hidden: tuple[int, ...] = (1024, 512)
    """Value MLP hidden sizes; one linear output unit (000 §4.1 "similar to the policy network")."""
    std_start: float = 0.5
    """Fixed (not learned) action std at the start of training (000 §4.1, Σ = σI, σ: 0.5 → 0.1)."""
    std_end: float = 0.1
    """Action std after the annealing period (000 §4.1)."""
    std_anneal_samples: float = 1.0e7
    """Samples over which σ decreases linearly, then stays at ``std_end`` (000 §4.1 "first 1.0×10^7
    simulation steps")."""
    std_schedule: list[list[float]] = dataclasses.field(default_factory=list)
    """Step-wise σ instead of the linear anneal: ``[[samples, std], ...]``, meaning "from this
    sample count on, use this std" (piecewise constant; sample counts strictly increasing, the
    first one 0). Empty (the default): the linear ``std_start`` → ``std_end`` anneal above. E.g.
    getup §5.6, 0.6 → 0.3 every 20M steps: ``[[0, 0.6], [2e7, 0.5], [4e7, 0.4], [6e7, 0.3]]``."""
    samples_per_iteration: int = 4096
    """State-action samples collected per iteration (000 §6.2); rounded up to a whole number of
    steps per environment."""
    epochs: int = 5
    """Passes over each batch (000 §6.2 "five policy updates"; code: ``epoch_size: 5``)."""
    minibatch_size: int = 256
    """Minibatch size (000 §6.2)."""
    clip: float = 0.02
    """PPO ratio clip threshold ε (000 §6.2)."""
    target_kl: Optional[float] = None
    """Stop an iteration's epochs once an epoch's mean approximate KL exceeds this (CleanRL's
    ``target_kl``); None: always ``epochs`` (the paper). Guards large-step settings (Adam, wide
    clip) against the overshoots docs/journal/jumping.md shows."""
    policy_lr: float = 2.5e-5
    """Policy learning rate (000 §6.2)."""
    value_lr: float = 1.0e-2
    """Value learning rate (000 §6.2)."""
    lr_schedule: list[list[float]] = dataclasses.field(default_factory=list)
    """Step-wise learning rates: ``[[samples, policy_lr, value_lr], ...]``, meaning "from this
    sample count on, use these rates" (piecewise constant; sample counts strictly increasing, the
    first one 0), written into both optimisers' ``param_groups`` at the start of every iteration
    (and then also logged as ``policy_lr`` / ``value_lr``). Empty (the default): the constant
    ``policy_lr`` and ``value_lr``. E.g. getup §5.6, 1e-4 → 2e-5 every 20M steps:
    ``[[0, 1e-4, 1e-3], [2e7, 6e-5, 1e-3], [4e7, 2e-5, 1e-3]]``."""
    optimizer: str = "sgd"
    """``sgd`` (with momentum) or ``adam``; separate optimisers for policy and value. The paper does
    not name it; the authors' code uses SGD with momentum (code ``ppo.yaml``), as DeepMimic does."""
    momentum: float = 0.9
    """SGD momentum (code ``actor_momentum``/``critic_momentum: 0.9``; paper silent)."""
    weight_decay: float = 5.0e-4
    """L2 weight decay of both optimisers (code ``actor_wdecay``/``critic_wdecay``; paper silent)."""
    max_grad_norm: float = 100.0
    """Gradient-norm clip per network; 0 disables (code ``max_grad_norm: 100``; paper silent)."""
    gamma: float = 1.0
    """Discount factor (000 §6.2 "short horizon and sparse rewards")."""
    lam: float = 0.95
    """λ of both TD(λ) value targets and GAE(λ) advantages (000 §6.2)."""
    norm_adv: bool = True
    """Standardise advantages over each batch (code; paper silent)."""
    adv_clip: float = 4.0
    """Clip standardised advantages to ±this; 0 disables (code; paper silent)."""
    obs_norm: bool = True
    """Running mean/std observation normalisation (DeepMimic lineage; code ``Normalizer``)."""
    obs_norm_max_samples: int = 1_000_000
    """Samples after which the normaliser's statistics freeze (code ``sample_lim``)."""
    normalize_actions: bool = False
    """False: the policy acts in the env's units and actions are clipped to its Box (as in the
    code, where σ is in raw action units); True: ``[-1, 1]`` mapped affinely onto the Box."""
    reward_scale: float = 1.0
    """Rewards are multiplied by this for learning only (reported returns stay raw); jt default 1."""
    reset_each_iteration: bool = True
    """True: every iteration starts new, seeded episodes in every environment (cut episodes are
    bootstrapped like time limits). False: episodes run on across iterations (an episode may be
    longer than one iteration's rollout; finished ones restart with the env's own RNG) and are
    restarted with seeded resets only at the start of a run or resume and after every checkpoint
    iteration (``iteration % checkpoint_every == 0``, whether or not a checkpoint file is
    written). Either way a run resumed from a checkpoint written at such an iteration is
    bit-identical to an uninterrupted one; with False, a resume from a checkpoint written at any
    other iteration (the budget's end, ``should_stop``) restarts the episodes there. jt choice,
    see docs/ppo.md."""
    total_samples: int = 100_000_000
    """Training budget in samples (not stated in 000; tasks set their own). 0 trains nothing (a
    warm start is then saved as it is)."""
    checkpoint_every: int = 100
    """Iterations between checkpoints (code ``checkpoint_every_iteration: 100``); also at the end.
    With ``reset_each_iteration=False`` also the episode-restart period."""
    seed: int = 0
    """Run seed: network init, minibatch order, every environment and action-noise seed."""
    n_workers: int = 1
    """Rollout workers (executor actors). With ``envs_per_worker`` it fixes the seed layout, so
    results do not depend on the executor."""
    envs_per_worker: int = 16
    """Environments per worker, stepped in lock-step (16 → 256 steps each per iteration)."""
    update_threads: int = 0
    """Torch threads of the driver's PPO update (0: torch's default, one per core). Where the
    rollout workers or another run share the cores, 1 keeps the update's threads from waiting on
    each other (docs/performance.md). Another value changes the update's floating-point sums, so
    the same seed gives the same result for the same value only."""

    def to_dict(self) -> dict[str, Any]:
        """JSON-able dict (tuples become lists)."""
        return json.loads(json.dumps(dataclasses.asdict(self)))

    def check(self, prefix: str = "agent") -> None:
        """Range-check every value.

        Args:
            prefix: the config group named in messages (``agent.minibatch_size=0: ...``).

        Raises:
            toolkit.errors.JtError: one line naming the first bad key, its value and the valid
                range, e.g. ``agent.minibatch_size=0: must be an integer >= 1``.
        """
        from toolkit.errors import JtError

        def bad(key: str, value: Any, why: str) -> JtError:
            return JtError(f"{prefix}.{key}={_show(value)}: {why}")

        for key in ("policy_hidden", "value_hidden"):
            sizes = getattr(self, key)
            if isinstance(sizes, (str, bytes)) or not isinstance(sizes, Sequence):
                raise bad(key, sizes, "must be a list of layer sizes (integers >= 1)")
            if not all(_is_int(h) and h >= 1 for h in sizes):
                raise bad(key, sizes, "must be a list of layer sizes (integers >= 1)")
        for key in ("epochs", "minibatch_size", "checkpoint_every", "n_workers", "envs_per_worker"):
            v = getattr(self, key)
            if not (_is_int(v) and v >= 1):
                raise bad(key, v, "must be an integer >= 1")
        if not (_is_int(self.update_threads) and self.update_threads >= 0):
            raise bad("update_threads", self.update_threads, "must be an integer >= 0 (0: torch's default)")
        if not (_is_int(self.seed) and self.seed >= 0):
            raise bad("seed", self.seed, "must be an integer >= 0")
        for key, low in (("samples_per_iteration", 1), ("total_samples", 0), ("obs_norm_max_samples", 0)):
            v = getattr(self, key)
            if not (_is_whole(v) and v >= low):
                raise bad(key, v, f"must be a whole number >= {low}")
        for key in ("std_start", "std_end", "clip", "policy_lr", "value_lr", "reward_scale"):
            v = getattr(self, key)
            if not (_is_real(v) and math.isfinite(v) and v > 0):
                raise bad(key, v, "must be a finite number > 0")
        for key in ("std_anneal_samples", "weight_decay"):
            v = getattr(self, key)
            if not (_is_real(v) and math.isfinite(v) and v >= 0):
                raise bad(key, v, "must be a finite number >= 0")
        for key in ("max_grad_norm", "adv_clip"):
            v = getattr(self, key)
            if not (_is_real(v) and not math.isnan(v) and v >= 0):
                raise bad(key, v, "must be a number >= 0 (0 disables)")
        for key in ("gamma", "lam", "momentum"):
            v = getattr(self, key)
            if not (_is_real(v) and 0.0 <= v <= 1.0):
                raise bad(key, v, "must be in [0, 1]")
        if self.target_kl is not None and not (_is_real(self.target_kl) and self.target_kl > 0):
            raise bad("target_kl", self.target_kl, "must be a number > 0, or null (always run every epoch)")
        if self.optimizer not in OPTIMIZERS:
            raise bad("optimizer", self.optimizer, f"must be one of {', '.join(OPTIMIZERS)}")
        for key in ("norm_adv", "obs_norm", "normalize_actions", "reset_each_iteration"):
            v = getattr(self, key)
            if not isinstance(v, bool):
                raise bad(key, v, "must be true or false")
        _check_schedule(self.std_schedule, 1, "[samples, std]", bad, "std_schedule")
        _check_schedule(self.lr_schedule, 2, "[samples, policy_lr, value_lr]", bad, "lr_schedule")


def scheduled(schedule: Sequence[Sequence[float]], samples: float) -> Optional[tuple[float, ...]]:
    """The values of the piecewise-constant ``schedule`` in force at ``samples``.

    Args:
        schedule: ``[[samples_i, value_i...], ...]``, ``samples_i`` increasing.
        samples: samples collected so far.

    Returns:
        ``value_i...`` of the last entry with ``samples_i <= samples`` (None if the schedule is
        empty or starts later).
    """
    current: Optional[tuple[float, ...]] = None
    for entry in schedule:
        if float(entry[0]) > samples:
            break
        current = tuple(float(v) for v in entry[1:])
    return current


def _check_schedule(schedule: Any, n_values: int, form: str, bad: Any, key: str) -> None:
    """Entries ``[samples, value...]``: samples whole, >= 0, strictly increasing, first 0; values > 0."""
    if isinstance(schedule, (str, bytes)) or not isinstance(schedule, Sequence):
        raise bad(key, schedule, f"must be a list of {form} entries (empty: off)")
    previous = -1.0
    for i, entry in enumerate(schedule):
        where = f"{key}[{i}]"
        if isinstance(entry, (str, bytes)) or not isinstance(entry, Sequence) or len(entry) != 1 + n_values:
            raise bad(where, entry, f"must be {form}")
        at, *values = entry
        if not (_is_whole(at) and at >= 0):
            raise bad(where, entry, "the sample count must be a whole number >= 0")
        if i == 0 and at != 0:
            raise bad(where, entry, "the first entry must start at 0 samples")
        if at <= previous:
            raise bad(where, entry, "sample counts must increase strictly")
        if not all(_is_real(v) and math.isfinite(v) and v > 0 for v in values):
            raise bad(where, entry, "values must be finite numbers > 0")
        previous = float(at)


def _is_int(v: Any) -> bool:
    return isinstance(v, numbers.Integral) and not isinstance(v, bool)


def _is_real(v: Any) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def _is_whole(v: Any) -> bool:
    """An integer, or a float holding one (``1e8`` from YAML)."""
    return _is_int(v) or (_is_real(v) and math.isfinite(v) and float(v).is_integer())


def _show(v: Any) -> str:
    if isinstance(v, str):
        return v
    if isinstance(v, bool):
        return str(v).lower()
    if v is None:
        return "null"
    if isinstance(v, tuple):
        v = list(v)
    return str(v)
