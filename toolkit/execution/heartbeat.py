"""Who owns a run on a server store, across machines: a heartbeat tag on the run itself.

The run lock (``toolkit.execution.lock``) is a file in the run's working folder, and a server
store keeps those folders in each driver's own cache: a ``resume=`` from a second machine does
not see the first machine's lock. So a driver of a run on a server store also keeps two tags on
the run: ``jt.owner`` (``pid N on HOST (since TIME)``, set once) and ``jt.heartbeat`` (Unix time),
renewed every ``PERIOD_S`` seconds by a daemon thread; ``stopped`` when the driver lets go.

A ``resume=`` from another host refuses a run whose heartbeat is younger than ``STALE_S``: its
owner is alive (or died within the last minute and a half: wait, then resume). Two resumes from
two hosts at once both write ``jt.owner``; each reads it back after ``CONFIRM_S`` and only the one
that finds its own name goes on (``Heartbeat.confirm``). On the owner's own host the lock decides,
which also sees a ``kill -9`` at once. A local store needs no heartbeat: one machine, the lock is
enough. The ages compare the clocks of two machines: they should agree within a minute (NTP).
"""

from __future__ import annotations

import datetime
import os
import socket
import threading
import time
from typing import Any, Optional

from toolkit.errors import JtError

OWNER_TAG = "jt.owner"
"""The driving process: ``pid N on HOST (since TIME)``."""
HEARTBEAT_TAG = "jt.heartbeat"
"""Unix time of the owner's last beat, or ``stopped``."""
PERIOD_S = 30.0
"""Seconds between two beats."""
STALE_S = 90.0
"""A heartbeat older than this is a dead owner's (three beats missed)."""
CONFIRM_S = 1.0
"""Seconds a resume waits before reading ``jt.owner`` back (``Heartbeat.confirm``)."""


def owner_text() -> str:
    """This process as ``jt.owner`` names it."""
    since = datetime.datetime.now().isoformat(timespec="seconds")
    return f"pid {os.getpid()} on {socket.gethostname()} (since {since})"


def _host_of(owner: str) -> str:
    """The host of a ``jt.owner`` text (``""`` when it names none)."""
    parts = owner.split(" on ", 1)
    return parts[1].split(" (", 1)[0] if len(parts) == 2 else ""


def check_not_owned(store: Any, run: Any, now: Optional[float] = None) -> None:
    """One ``JtError`` line when another host's live driver owns ``run`` (a server store only).

    Args:
        store: the store (nothing to check unless ``store.is_server``).
        run: the MLflow run as just read.
        now: the time to compare the heartbeat with (``time.time()``).
    """
    if not getattr(store, "is_server", False):
        return
    tags = run.data.tags
    owner, beat = tags.get(OWNER_TAG, ""), tags.get(HEARTBEAT_TAG, "")
    if not owner or _host_of(owner) == socket.gethostname():
        return  # never owned through a server, or owned here: the lock file decides
    try:
        age = (time.time() if now is None else now) - float(beat)
    except ValueError:  # "stopped", or garbage
        return
    if age < STALE_S:
        rid = run.info.run_id
        raise JtError(f"run {rid} is being run by {owner} (its heartbeat is {max(age, 0.0):.0f} s old); a "
                      f"second resume would evaluate its points twice: wait for it to end, or stop it, wait "
                      f"{STALE_S:.0f} s and run jt run resume={rid} store={store.root} on the machine "
                      "that holds its working folder")


class Heartbeat:
    """The beating of one run's ``jt.heartbeat`` tag by this process (a server store only).

    Args:
        store: the store (``start`` does nothing unless ``store.is_server``).
        run_id: the run.
        period_s: seconds between two beats.
    """

    def __init__(self, store: Any, run_id: str, period_s: float = PERIOD_S) -> None:
        self.store, self.run_id, self.period_s = store, run_id, float(period_s)
        self._stop = threading.Event()
        self._thread: Optional[threading.Thread] = None
        self.owner = ""

    def start(self) -> "Heartbeat":
        """Set ``jt.owner`` and the first beat, then beat in a daemon thread; returns self."""
        if not getattr(self.store, "is_server", False) or self._thread is not None:
            return self
        from mlflow.tracking import MlflowClient

        from mlflow.entities import RunTag

        client = MlflowClient(tracking_uri=self.store.uri)  # its own client: no sharing across threads
        self.owner = owner_text()
        client.log_batch(self.run_id, tags=[RunTag(OWNER_TAG, self.owner),  # one call: never an owner
                                            RunTag(HEARTBEAT_TAG, f"{time.time():.0f}")])  # without a beat

        def beat() -> None:
            while not self._stop.wait(self.period_s):
                try:
                    client.set_tag(self.run_id, HEARTBEAT_TAG, f"{time.time():.0f}")
                except Exception:  # noqa: BLE001 - a server that is down for a moment: beat again later
                    pass

        self._thread = threading.Thread(target=beat, name="jt-heartbeat", daemon=True)
        self._thread.start()
        return self

    def confirm(self, wait_s: float = CONFIRM_S) -> None:
        """After ``wait_s``, check that ``jt.owner`` still names this process (a resume from
        another host at the same moment may have written it last); a server store only.

        Raises:
            JtError: another process took the run (this one stops beating first).
        """
        if self._thread is None:
            return
        time.sleep(wait_s)
        run = self.store.get_run(self.run_id)
        owner = run.data.tags.get(OWNER_TAG, "")
        if owner != self.owner:
            self._stop.set()
            self._thread.join(timeout=5.0)
            self._thread = None
            raise JtError(f"run {self.run_id} was taken a moment ago by {owner or 'another process'}; "
                          "this resume stops (one driver per run)")

    def stop(self) -> None:
        """Stop beating and mark the run ``stopped`` (best effort: a dead server just goes stale;
        a beat still being retried after 5 s leaves the mark out rather than be overwritten)."""
        if self._thread is None:
            return
        self._stop.set()
        self._thread.join(timeout=5.0)
        alive, self._thread = self._thread.is_alive(), None
        if alive:
            return
        try:
            self.store.client.set_tag(self.run_id, HEARTBEAT_TAG, "stopped")
        except Exception:  # noqa: BLE001
            pass
