"""Shared plumbing of jt's curricula: config parsing and the PPO ``on_iteration`` glue."""

from __future__ import annotations

import abc
import math
from typing import Any

from toolkit.interfaces.curriculum import Curriculum
from toolkit.config import config_of


def finite_or(value: Any, default: float = 0.0) -> float:
    """``float(value)``, or ``default`` for None / NaN / inf (e.g. an iteration with no episode)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        return default
    return v if math.isfinite(v) else default


class IterationCurriculum(Curriculum):
    """A curriculum driven by the PPO trainer's ``on_iteration`` hook.

    Use::

        cur = load("curriculum", name)(cfg.curriculum)
        extra = cur.bind({})                     # the dict given to ppo.train(extra=...)
        env_fn = make_env_fn(**cur.env_attrs())  # the first iteration's difficulty
        ppo.train(env_fn, ..., on_iteration=cur.on_iteration, extra=extra)

    ``on_iteration`` feeds every finished episode to ``update``, the iteration's scalar stats to
    ``end_iteration``, stores ``state()`` in ``extra`` (checkpointed by the trainer) and returns
    ``env_attrs()`` for the trainer to set on every environment. On resume the trainer replaces
    ``extra`` in place with the checkpoint's; the first ``on_iteration`` call then loads it.

    Args:
        cfg: the ``curriculum`` config group.
    """

    #: key of this curriculum's state inside the trainer's ``extra`` dict
    extra_key = "curriculum"

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        self.params = config_of(type(self).Config, cfg, f"curriculum={type(self).name or type(self).__name__}")

    @abc.abstractmethod
    def end_iteration(self, iteration: int, samples: int, stats: Any) -> None:
        """Account for one finished training iteration (after its episodes went to ``update``).

        Args:
            iteration: iterations done so far (1-based).
            samples: samples collected so far.
            stats: the trainer's scalar stats of the iteration (``mean_return``, ``mean_reward``...).
        """

    @abc.abstractmethod
    def env_attrs(self) -> dict[str, Any]:
        """Attributes to set on every environment for the current difficulty."""

    def frozen(self) -> bool:
        """True once training may stop (e.g. ``z_freeze`` reached); never for a plain curriculum."""
        return False

