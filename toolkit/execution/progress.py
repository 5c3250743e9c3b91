"""A run's progress on the terminal: one live bar for the run, one nested bar per running evaluation.

``RunProgress`` is made by the runner for its search loop. On a terminal (stderr is a TTY, no
``CI``, ``TERM`` not ``dumb``) it draws with ``rich``: the run's bar counts evaluations (a running
evaluation counts by the fraction it reports, e.g. PPO samples of its budget) with elapsed time,
ETA and the newest key figure; under it one bar per running evaluation with its own message. Off a
terminal (a pipe, a log file, CI) it writes plain lines, never control characters: at most one
progress line per ``LINE_EVERY_S`` seconds, plus every line the runner logs (one per finished
evaluation). ``JT_PROGRESS=lines|bar`` forces either.

Evaluations report with ``update(index, fraction, message)``: directly when they run in this
process, through ``Channel`` (a queue the executor provides, ``Executor.progress_queue``) when they
run in its worker processes; ``pump`` drains that queue on a thread of the driver.
"""

from __future__ import annotations

import math
import os
import queue as queue_mod
import sys
import threading
import time
from typing import Any, Optional

LINE_EVERY_S = 10.0  #: seconds between progress lines off a terminal
QUIET_S = 2.0  #: an evaluation shows progress only once it has run this long


MODES = ("bar", "lines")  #: what JT_PROGRESS may force


def check_env() -> None:
    """One ``JtError`` line for a ``JT_PROGRESS`` that names no mode (it would be ignored)."""
    forced = os.environ.get("JT_PROGRESS", "").strip().lower()
    if forced and forced not in MODES:
        from toolkit.errors import JtError

        raise JtError(f"JT_PROGRESS={os.environ['JT_PROGRESS']!r}: choose bar or lines "
                      "(unset: a bar on a terminal, lines elsewhere)")


def mode() -> str:
    """``bar`` on an interactive terminal, else ``lines`` (``JT_PROGRESS`` overrides)."""
    forced = os.environ.get("JT_PROGRESS", "").strip().lower()
    if forced in ("bar", "lines"):
        return forced
    tty = hasattr(sys.stderr, "isatty") and sys.stderr.isatty()
    if not tty or os.environ.get("CI") or os.environ.get("TERM", "") == "dumb":
        return "lines"
    return "bar"


def clock(seconds: float) -> str:
    """``h:mm:ss`` (or ``m:ss`` under an hour)."""
    s = int(max(seconds, 0.0) + 0.5)
    h, m = divmod(s, 3600)
    m, s = divmod(m, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


def figure(value: Any, fmt: str = ".3g", missing: str = "—") -> str:
    """``value`` formatted for a progress message, ``missing`` where it does not exist yet (None, NaN,
    inf): a user reads ``success —``, never ``success nan``."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        return missing
    return format(v, fmt) if math.isfinite(v) else missing


class Channel:
    """What an evaluation in a worker process reports through: ``put((index, fraction, message))``
    onto the executor's queue (picklable with the job)."""

    def __init__(self, q: Any) -> None:
        self.q = q

    def __call__(self, index: int, fraction: float, message: str = "") -> None:
        try:
            self.q.put_nowait((int(index), float(fraction), str(message)))
        except Exception:  # noqa: BLE001 - progress is never worth failing an evaluation for
            pass


class RunProgress:
    """The run's progress display (see the module docstring).

    Args:
        total: evaluations the run will make; done: those already made (a resumed run).
        label: what the run's bar is called (``task=getup``).
        out: the stream (stderr); console: a ``rich`` console to draw on (tests).
        how: ``bar`` or ``lines`` (default ``mode()``).
    """

    def __init__(self, total: int, done: int = 0, label: str = "run", out: Any = None,
                 console: Any = None, how: Optional[str] = None) -> None:
        self.total, self.done, self.label = max(int(total), 1), int(done), label
        self.out = out if out is not None else sys.stderr
        self.how = how or ("bar" if console is not None else mode())
        self.running: dict[int, list] = {}  # index -> [fraction, message, started]
        self.figure = ""
        self.t0 = time.monotonic()
        self.done0 = self.done
        self.last_line = 0.0
        self.lock = threading.Lock()
        self.bar = None
        if self.how == "bar":
            from rich.console import Console
            from rich.progress import (BarColumn, Progress, TaskProgressColumn, TextColumn, TimeElapsedColumn,
                                       TimeRemainingColumn)

            self.bar = Progress(TextColumn("{task.description}"), BarColumn(), TaskProgressColumn(),
                                TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(),
                                TextColumn("{task.fields[figure]}"),
                                console=console or Console(file=self.out), redirect_stdout=False,
                                redirect_stderr=console is None, refresh_per_second=4)
            self.run_task = self.bar.add_task(f"{label} {self.done}/{self.total}", total=self.total,
                                              completed=self.done, figure="")
            self.eval_tasks: dict[int, Any] = {}
            self.bar.start()

    # ------------------------------------------------------------------ what the runner calls
    def update(self, index: int, fraction: float, message: str = "") -> None:
        """Evaluation ``index`` has done ``fraction`` of its work; ``message`` its key figure now."""
        with self.lock:
            entry = self.running.setdefault(int(index), [0.0, "", time.monotonic()])
            entry[0], entry[1] = min(max(float(fraction), 0.0), 1.0), str(message)
            self.figure = str(message) or self.figure
            if self.bar is not None:
                self._draw(int(index))
            else:
                self._line(int(index))

    def finished(self, index: int, line: str) -> None:
        """Evaluation ``index`` ended; ``line`` is the runner's line about it."""
        with self.lock:
            self.running.pop(int(index), None)
            self.done += 1
            if self.bar is not None:
                task = self.eval_tasks.pop(int(index), None)
                if task is not None:
                    self.bar.remove_task(task)
                self.bar.update(self.run_task, completed=self.done + self._partial(),
                                description=f"{self.label} {self.done}/{self.total}")
                self.bar.console.print(line, highlight=False, markup=False)
            else:
                print(line, file=self.out, flush=True)

    def log(self, line: str) -> None:
        """A line above the bar (or a plain line)."""
        with self.lock:
            if self.bar is not None:
                self.bar.console.print(line, highlight=False, markup=False)
            else:
                print(line, file=self.out, flush=True)

    def close(self) -> None:
        """Stop drawing (the bar stays on screen as it last was)."""
        if self.bar is not None:
            self.bar.stop()
            self.bar = None

    # ------------------------------------------------------------------ drawing
    def _partial(self) -> float:
        return sum(e[0] for e in self.running.values())

    def fraction(self) -> float:
        """The run's share done, running evaluations by their fractions."""
        return min((self.done + self._partial()) / self.total, 1.0)

    def eta(self) -> Optional[float]:
        """Seconds left at this process's pace so far (None before any progress)."""
        made = self.done - self.done0 + self._partial()
        if made <= 0:
            return None
        elapsed = time.monotonic() - self.t0
        return elapsed * (self.total - self.done - self._partial()) / made

    def _draw(self, index: int) -> None:
        frac, msg, started = self.running[index]
        if time.monotonic() - started < QUIET_S and frac < 1.0 and index not in self.eval_tasks:
            return
        if index not in self.eval_tasks:
            self.eval_tasks[index] = self.bar.add_task(f"  eval {index}", total=1.0, figure="")
        self.bar.update(self.eval_tasks[index], completed=frac, figure=msg)
        self.bar.update(self.run_task, completed=self.done + self._partial(), figure=self.figure)

    def _line(self, index: int) -> None:
        now = time.monotonic()
        frac, msg, started = self.running[index]
        if now - started < QUIET_S or now - self.last_line < LINE_EVERY_S:
            return
        self.last_line = now
        eta = self.eta()
        print(f"  {self.label}: {100 * self.fraction():5.1f}% ({self.done}/{self.total} done), elapsed "
              f"{clock(now - self.t0)}, ETA {clock(eta) if eta is not None else '—'} | eval {index}: "
              f"{100 * frac:5.1f}% {msg}", file=self.out, flush=True)

    def pump(self, q: Any) -> "Pump":
        """Drain ``q`` (``(index, fraction, message)`` items) into ``update`` on a thread."""
        return Pump(self, q)


class Pump:
    """A driver thread that moves worker reports from a queue to ``RunProgress.update``."""

    def __init__(self, progress: RunProgress, q: Any) -> None:
        self.progress, self.q = progress, q
        self.stop_ = threading.Event()
        self.thread = threading.Thread(target=self._loop, name="jt-progress", daemon=True)
        self.thread.start()

    def _loop(self) -> None:
        while not self.stop_.is_set():
            try:
                index, fraction, message = self.q.get(timeout=0.2)
            except queue_mod.Empty:
                continue
            except (EOFError, OSError):  # the executor's queue went away
                return
            self.progress.update(index, fraction, message)

    def stop(self) -> None:
        """Stop draining."""
        self.stop_.set()
        self.thread.join(timeout=2.0)
