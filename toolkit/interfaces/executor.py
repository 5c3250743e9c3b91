"""Executors (``jt.executors``): run independent evaluations, and long-lived workers, in parallel."""

from __future__ import annotations

import abc
from typing import Any, Callable, Iterator, Sequence

from toolkit.interfaces.plugin import Plugin


class ActorGroup(abc.ABC):
    """Long-lived workers, each owning an object (e.g. a simulator), called in lock-step."""

    @abc.abstractmethod
    def call(self, method: str, args: Sequence[tuple] | None = None) -> list[Any]:
        """Call ``method`` on every actor (actor ``i`` gets ``*args[i]``); results in actor order."""

    @abc.abstractmethod
    def close(self) -> None:
        """Stop the workers."""

    def __len__(self) -> int:  # pragma: no cover - trivial
        return self.size

    size: int = 0


class Executor(Plugin, abc.ABC):
    """Runs picklable work in parallel.

    Two shapes of work: ``imap``/``map`` run a module-level function over independent items (a
    searcher's evaluations); ``actors`` starts long-lived workers that own state (PPO's rollout
    workers, each with its own simulator). Every item or actor carries its own seed, so results do
    not depend on which worker ran it or in which order work finishes.

    Args:
        cfg: the ``executor`` config group, validated against ``Config``.
    """

    def __init__(self, cfg: Any) -> None:
        self.cfg = cfg

    @abc.abstractmethod
    def imap(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> Iterator[tuple[int, Any]]:
        """Yield ``(index, fn(items[index]))`` in completion order."""

    def map(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> list[Any]:
        """``[fn(x) for x in items]``, computed in parallel, in input order."""
        out: list[Any] = [None] * len(items)
        for i, r in self.imap(fn, items):
            out[i] = r
        return out

    @abc.abstractmethod
    def actors(self, factory: Callable[..., Any], args: Sequence[tuple]) -> ActorGroup:
        """Start ``len(args)`` workers; worker ``i`` holds ``factory(*args[i])``."""

    @property
    def n_workers(self) -> int:
        """How many items run at once."""
        return 1

    def close(self) -> None:
        """Release workers."""

    def __enter__(self) -> "Executor":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
