"""Stopping a run at a safe point when asked to (SIGTERM, Ctrl-C).

A signal handler must not raise: an exception raised from it lands wherever the main thread
happens to be, inside a weakref callback (where Python prints it and swallows it, and the run goes
on to FINISHED) or halfway through an MLflow/SQLite write (``database is locked``, the run left
RUNNING). So ``Terminate`` only records the request, and the run stops at its next safe point by
calling ``check()``: between evaluations and store writes (the runner), after each PPO iteration
(``toolkit.rl.ppo``), between episodes of a final evaluation (``toolkit.policy.episodes.rollout``),
while the local executor waits for its workers. ``check()`` raises ``KeyboardInterrupt`` with the
reason, which the runner turns into a KILLED run (exit 130, resumable). A second SIGTERM while
the first is pending raises at once (a run stuck somewhere can still be stopped).

SIGHUP (the terminal closed: a window shut, an ssh session dropped) is a stop request like SIGTERM;
since the terminal is gone, the process's stdout and stderr are pointed at /dev/null first, so
the lines said while stopping cannot fail on a dead terminal. Where SIGHUP is ignored (``nohup``)
it stays ignored.

Ctrl-C (SIGINT) is handled the same way while a run is open: Python's own handler raises
``KeyboardInterrupt`` wherever the main thread is, and one that lands in a weakref callback or a
``__del__`` is printed and swallowed, so the run went on to FINISHED. The first Ctrl-C now asks for
a stop at the next safe point (one line says so), a second stops at once. Where SIGINT is ignored
(a shell's background job) it stays ignored.
"""

from __future__ import annotations

import os
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
    """While a run is open, SIGTERM or Ctrl-C requests a stop at the next safe point (``check``); a
    second one raises ``KeyboardInterrupt`` at once. Outside the main thread it changes nothing;
    an ignored SIGINT (a background job) stays ignored."""

    REASON = "terminated (SIGTERM)"
    REASON_INT = "interrupted (Ctrl-C)"
    REASON_HUP = "hung up (SIGHUP: the terminal closed)"
    _depth = 0  #: open Terminate blocks (a comparison's cells run inside its own)

    def __enter__(self) -> "Terminate":
        if Terminate._depth == 0:
            clear()
        Terminate._depth += 1
        self._old: dict[int, Any] = {}

        def handler(signum: int, frame: Any) -> None:
            reason = {signal.SIGINT: self.REASON_INT, signal.SIGHUP: self.REASON_HUP}.get(signum, self.REASON)
            if signum == signal.SIGHUP:
                _detach_from_terminal()
            if requested() is not None:
                raise KeyboardInterrupt(reason)
            request(reason)
            if signum == signal.SIGINT:  # os.write: no buffered I/O inside a signal handler
                os.write(2, b"\njt: stopping at the next safe point (Ctrl-C again to stop now)\n")

        for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
            old = signal.getsignal(sig)
            if sig == signal.SIGINT and old is not signal.default_int_handler:
                continue  # ignored (a background job) or someone else's: left as it is
            if sig == signal.SIGHUP and old is not signal.SIG_DFL:
                continue  # ignored (nohup) or someone else's: left as it is
            try:
                signal.signal(sig, handler)
            except ValueError:  # not the main thread
                break
            self._old[sig] = old
        return self

    def __exit__(self, *exc: Any) -> None:
        Terminate._depth -= 1
        for sig, old in self._old.items():
            signal.signal(sig, old)
        if Terminate._depth == 0:
            clear()


def _detach_from_terminal() -> None:
    """Point file descriptors 1 and 2 at /dev/null (the terminal that had them is gone: a write
    would fail with EIO and break the stop's own lines)."""
    try:
        null = os.open(os.devnull, os.O_WRONLY)
    except OSError:
        return
    for fd in (1, 2):
        try:
            os.dup2(null, fd)
        except OSError:
            pass
    os.close(null)
