"""Curricula (``jt.curricula``): difficulty state updated from training statistics."""

from __future__ import annotations

import abc
from typing import Any, ClassVar

from toolkit.interfaces.plugin import GroupPlugin


class Curriculum(GroupPlugin, abc.ABC):
    """Holds a difficulty state and updates it from episode outcomes.

    Required: ``update``, ``state``, ``load_state``. What the policy tasks call, with defaults:
    ``bind(extra)`` (keep the state in the trainer's checkpointed dict), ``on_iteration(...)``
    (the PPO trainer's per-iteration hook: episodes to ``update``, state back into ``extra``,
    returns ``env_attrs()``), ``env_attrs()`` (none) and ``frozen()`` (never: when training may
stop early). ``jt_curricula.base.IterationCurriculum``
    is the fuller base the built-ins use.

    Attributes:
        extra_key: key of this curriculum's state inside the trainer's ``extra`` dict.

    Args:
        cfg: the ``curriculum`` config group, validated against ``Config``.
    """

    what: ClassVar[str] = "curriculum={name}"

    extra_key: ClassVar[str] = "curriculum"

    @classmethod
    def drives(cls, params: Any) -> set[str]:
        """The environment attributes this curriculum sets (``env_attrs``) with ``params``: by
        default the values of its fields ending in ``_attr``. Composition checks them against the
        task's declared ``Task.curriculum_attrs``; a curriculum that sets others overrides this."""
        items = params.items() if hasattr(params, "items") else vars(params).items()
        return {str(v) for k, v in items if str(k).endswith("_attr") and v}

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)

    @abc.abstractmethod
    def update(self, episode: dict[str, Any]) -> None:
        """Account for one finished episode's statistics."""

    @abc.abstractmethod
    def state(self) -> dict[str, float]:
        """Current difficulty values (saved in checkpoints, logged as metrics)."""

    @abc.abstractmethod
    def load_state(self, state: dict[str, float]) -> None:
        """Restore a saved ``state()``."""

    def env_attrs(self) -> dict[str, Any]:
        """Attributes to set on every environment for the current difficulty (none by default)."""
        return {}

    def frozen(self) -> bool:
        """True once training should stop at the reached difficulty (the jumps stop at
        ``z_freeze``, ``000`` §6.1.4); never by default."""
        return False

    def end_iteration(self, iteration: int, samples: int, stats: Any) -> None:
        """Account for one finished training iteration, after its episodes went to ``update``
        (nothing by default)."""

    def bind(self, extra: dict[str, Any]) -> dict[str, Any]:
        """Keep this curriculum's state in ``extra[extra_key]`` (the trainer's checkpointed dict);
        on resume the trainer refills ``extra`` in place and the next ``on_iteration`` loads it.

        Returns:
            ``extra`` itself, holding the current ``state()`` unless it already holds a saved one.
        """
        self._bound_extra = extra
        self._bound_synced = False
        extra.setdefault(self.extra_key, dict(self.state()))
        return extra

    def on_iteration(self, iteration: int, samples: int, stats: Any) -> dict[str, Any]:
        """The PPO trainer's hook after each iteration: every finished episode of ``stats.episodes``
        goes to ``update``, then ``end_iteration``; returns ``env_attrs()`` for the trainer to set on
        every environment."""
        extra = getattr(self, "_bound_extra", None)
        if extra is not None and not getattr(self, "_bound_synced", True):
            saved = extra.get(self.extra_key)
            if saved:
                self.load_state(dict(saved))
            self._bound_synced = True
        for episode in getattr(stats, "episodes", ()) or ():
            self.update(episode)
        self.end_iteration(iteration, samples, stats)
        if extra is not None:
            extra[self.extra_key] = dict(self.state())
        return self.env_attrs()
