"""``InlineActors``: an ``ActorGroup`` whose actors live in this process.

What an executor hands out when no process is worth starting (one worker, or ``workers=1``), and
what PPO uses without an executor. Same call shape as the process and Ray actor groups, so callers
never branch on where their workers run.
"""

from __future__ import annotations

from typing import Any, Callable, Sequence

from toolkit.interfaces import ActorGroup


class InlineActors(ActorGroup):
    """Actors built and called in this process, in order."""

    def __init__(self, factory: Callable[..., Any], args: Sequence[tuple]) -> None:
        self._objs = [factory(*a) for a in args]
        self.size = len(self._objs)

    def call(self, method: str, args: Sequence[tuple] | None = None) -> list[Any]:
        """Call ``method`` on every actor in order (actor ``i`` gets ``*args[i]``)."""
        args = args if args is not None else [()] * self.size
        return [getattr(o, method)(*a) for o, a in zip(self._objs, args)]

    def close(self) -> None:
        """Close every actor that has a ``close``."""
        for o in self._objs:
            close = getattr(o, "close", None)
            if callable(close):
                close()
        self._objs = []
