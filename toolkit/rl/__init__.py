"""PPO for jt (000 §4.1, §6.2): config, training loop, rollout workers, networks, checkpoints.

Modules:

* ``config``: ``PPOConfig``, every hyper-parameter with its source and range check (torch-free);
* ``ppo``: the training loop (``train``), GAE, learning-rate and action-std schedules;
* ``rollout``: rollout workers, each owning a few environments and a CPU copy of the policy;
* ``networks``: the policy and value networks, the Gaussian log-density, action bounds;
* ``checkpoint``: PPO checkpoints as HDF5 files (save, resume, warm start);
* ``gym_check``: the gymnasium API check every jt task's env passes;
* ``sanity``: the sanity benchmark (PPO learns ``Pendulum-v1``);
* ``rollout_bench``, ``train_bench``: ``jt bench rollout`` (where an env spends its time,
  collection and training speed).

Importing this package imports nothing heavy: ``toolkit.rl.config`` (``PPOConfig``) is torch-free,
and the names below are loaded on first use (``toolkit.rl.ppo`` imports torch).
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS = {
    "PPOConfig": "toolkit.rl.config",
    "IterationStats": "toolkit.rl.ppo",
    "TrainResult": "toolkit.rl.ppo",
    "action_std": "toolkit.rl.ppo",
    "compute_gae": "toolkit.rl.ppo",
    "learning_rates": "toolkit.rl.ppo",
    "train": "toolkit.rl.ppo",
    "architecture_of": "toolkit.rl.checkpoint",
    "with_architecture": "toolkit.rl.checkpoint",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        return getattr(importlib.import_module(_EXPORTS[name]), name)
    raise AttributeError(f"module 'toolkit.rl' has no attribute {name!r}")
