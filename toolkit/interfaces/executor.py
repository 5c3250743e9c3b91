"""Executors (``jt.executors``): run independent evaluations, and long-lived workers, in parallel."""

from __future__ import annotations

import abc
import dataclasses
from typing import Any, Callable, ClassVar, Iterator, Optional, Sequence

from toolkit.interfaces.plugin import Plugin


@dataclasses.dataclass
class ExecutorKeys:
    """Keys of the ``executor`` group that every executor accepts, declared by the interface.

    jt sets them itself (``experiment=smoke``, ``jt compare``), whichever executor is chosen. An
    executor that acts on one declares it in its own ``Config`` (same name, type and default)
    and reads it from there; in the group of one whose ``Config`` does not, the key is still
    accepted and type-checked at composition, then left out of the node the executor is built
    from: its ``Config`` stays exactly the keys it declares.
    """

    workers: int = 0
    """How many evaluations or actors run at once. 0: the executor's own choice (the default:
    one per core for ``executor=local``, as many as the cluster has CPUs for with ``executor=ray``,
    always one for a serial executor); 1: one at a time, in the driver's process where the
    executor can (``experiment=smoke``, and the runs inside a parallel ``jt compare``'s cells,
    so that cores are not oversubscribed); N > 1: at most N at once."""

    def check(self) -> None:
        """``workers`` >= 0 (one ``JtError`` line)."""
        from toolkit.schema import require

        require(int(self.workers) >= 0, "executor.workers", self.workers,
                "a count of workers >= 0 (0: the executor's own choice, 1: one at a time)")


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

    The ``executor`` group also takes the keys of ``common_keys`` (``ExecutorKeys``: ``workers``)
    whether or not ``Config`` declares them; declare ``workers: int = 0`` in ``Config`` to act on
    it (a parallel executor should: ``experiment=smoke`` and ``jt compare`` ask for one at a time
    with ``workers=1``).

    Args:
        cfg: the ``executor`` config group, validated against ``Config``.

    Attributes:
        common_keys: the dataclass of the keys every executor's group accepts (``ExecutorKeys``);
            read by composition (``toolkit.schema``), not meant to be overridden by a plugin.
    """

    common_keys: ClassVar[type] = ExecutorKeys

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

    def runs_inline(self, n_items: int) -> bool:
        """Whether ``imap`` over ``n_items`` items runs them in this process (default: no), so
        that they may report to the driver by a plain call."""
        return False

    def progress_queue(self) -> Optional[Any]:
        """A queue (``put_nowait``, ``get(timeout=)``) that work running in this executor's workers
        can reach from there, to report progress to the driver; None (the default): none, and
        long evaluations in workers print their own progress lines."""
        return None

    def close(self) -> None:
        """Release workers."""

    def __enter__(self) -> "Executor":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
