"""PPO for jt (000 §4.1, §6.2): config, training loop, rollout workers, networks, checkpoints.

Importing this package imports nothing heavy: ``toolkit.rl.config`` (``PPOConfig``) is torch-free,
and the names below are loaded on first use (``toolkit.rl.train`` imports torch).
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
