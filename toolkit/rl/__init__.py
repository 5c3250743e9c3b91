"""PPO for jt (000 §4.1, §6.2): config, training loop, rollout workers, networks, checkpoints.

Importing this package imports torch; it is only imported when training.
"""

from toolkit.rl.ppo import IterationStats, PPOConfig, TrainResult, action_std, compute_gae, train

__all__ = ["IterationStats", "PPOConfig", "TrainResult", "action_std", "compute_gae", "train"]
