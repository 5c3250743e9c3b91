"""Stopping a run at a safe point when asked to (SIGTERM).

A signal handler must not raise: an exception raised from it lands wherever the main thread
happens to be, inside a weakref callback (where Python prints it and swallows it, and the run goes
on to FINISHED) or halfway through an MLflow/SQLite write (``database is locked``, the run left
RUNNING). So ``Terminate`` only records the request, and the run stops at its next safe point by
calling ``check()``: between evaluations and store writes (the runner), after each PPO iteration
(``toolkit.rl.ppo``), between episodes of a final evaluation (``toolkit.policy.train.rollout``),
while the local executor waits for its workers. ``check()`` raises ``KeyboardInterrupt`` with the
reason, which the runner turns into a KILLED run (exit 130, resumable). A second SIGTERM while
the first is pending raises at once (a run stuck somewhere can still be stopped).
"""

from __future__ import annotations

import signal
from typing import Any, Optional

_REQUEST: dict[str, Optional[str]] = {"reason": None}


def request(reason: str) -> None:
    """Ask the run in this process to stop at its next safe point."""
    _REQUEST["reason"] = reason


def requested() -> Optional[str]:
    """The pending request's reason, or None."""
    return _REQUEST["reason"]


def clear() -> None:
    """Forget a pending request (a new run starts)."""
    _REQUEST["reason"] = None


def check() -> None:
    """A safe point: raise ``KeyboardInterrupt(reason)`` if a stop was requested.

    Raises:
        KeyboardInterrupt: a stop is pending (the runner marks the run KILLED with the reason).
    """
    reason = _REQUEST["reason"]
    if reason is not None:
        raise KeyboardInterrupt(reason)


class Terminate:
    """While a run is open, SIGTERM requests a stop at the next safe point (``check``); a second
    SIGTERM raises ``KeyboardInterrupt`` at once. Outside the main thread it changes nothing."""

    REASON = "terminated (SIGTERM)"
    _depth = 0  #: open Terminate blocks (a comparison's cells run inside its own)

    def __enter__(self) -> "Terminate":
        if Terminate._depth == 0:
            clear()
        Terminate._depth += 1
        self._old: Any = signal.getsignal(signal.SIGTERM)

        def handler(signum: int, frame: Any) -> None:
            if requested() is not None:
                raise KeyboardInterrupt(self.REASON)
            request(self.REASON)

        try:
            signal.signal(signal.SIGTERM, handler)
        except ValueError:  # not the main thread
            self._old = None
        return self

    def __exit__(self, *exc: Any) -> None:
        Terminate._depth -= 1
        if self._old is not None:
            signal.signal(signal.SIGTERM, self._old)
        if Terminate._depth == 0:
            clear()
