"""Who owns a run: a lock file in the run's working folder, held for as long as a process drives it.

``jt run`` takes the lock as soon as its run exists and ``jt run resume=RUN_ID`` before it touches
the run, so a second resume of a run that a live process drives is refused (one line naming the
owner's pid and host) instead of evaluating the same points twice.

The lock is a POSIX record lock (``fcntl.lockf``) on ``<workdir>/run.lock``: the kernel drops it
when its process ends, however it ends (``kill -9`` included), so a dead owner never blocks a
resume; and unlike ``flock`` it is not inherited by processes the owner forks (pool workers), so
an evaluation worker outliving its driver for a moment does not hold it. The file's content (pid,
host, start time) only names the owner in the refusal; the lock itself is what counts.

One caveat of POSIX locks: closing *any* descriptor of the file drops the process's lock, so
nothing else in the owning process may open ``run.lock`` (``Store.log_artifacts`` skips
``*.lock`` files).
"""

from __future__ import annotations

import datetime
import errno
import fcntl
import json
import os
import socket
from pathlib import Path
from typing import Optional

from toolkit.errors import JtError

LOCK_NAME = "run.lock"
"""The lock file's name in a run's working folder."""


def _owner_text(fd: int) -> str:
    """``pid N on HOST (since TIME)`` from the lock file's content, or a vaguer phrase."""
    try:
        os.lseek(fd, 0, os.SEEK_SET)
        info = json.loads(os.read(fd, 4096).decode() or "{}")
    except (OSError, ValueError):
        info = {}
    if not info.get("pid"):
        return "another jt process (it is still starting)"
    since = f" (since {info['since']})" if info.get("since") else ""
    return f"pid {info['pid']} on {info.get('host', '?')}{since}"


class RunLock:
    """The ownership of one run by this process (see the module docstring).

    Args:
        workdir: the run's working folder (``Store.workdir(run_id)``).
        run_id: the run, for the refusal's message.

    Attributes:
        path: the lock file.
    """

    def __init__(self, workdir: Path, run_id: str) -> None:
        self.path = Path(workdir) / LOCK_NAME
        self.run_id = run_id
        self._fd: Optional[int] = None
        self._attached: list = []

    @property
    def held(self) -> bool:
        """Whether this process holds the lock."""
        return self._fd is not None

    def acquire(self, store_root: str = "") -> "RunLock":
        """Take the lock without waiting, and write this process's pid, host and time into it.

        Args:
            store_root: the store, for the refusal's hint.

        Returns:
            self.

        Raises:
            JtError: another live process holds it (the message names that process).
        """
        if self._fd is not None:
            return self
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as e:
            if e.errno not in (errno.EACCES, errno.EAGAIN):
                os.close(fd)
                raise
            owner = _owner_text(fd)
            os.close(fd)
            where = f" store={store_root}" if store_root else ""
            raise JtError(f"run {self.run_id} is already being run by {owner}; a second resume would "
                          f"evaluate its points twice: wait for it to end, or stop it and then run "
                          f"jt run resume={self.run_id}{where}") from None
        try:
            info = {"pid": os.getpid(), "host": socket.gethostname(),
                    "since": datetime.datetime.now().isoformat(timespec="seconds")}
            os.ftruncate(fd, 0)
            os.lseek(fd, 0, os.SEEK_SET)
            os.write(fd, json.dumps(info).encode())
        except OSError:  # a full disk: the lock still holds, only the refusal is vaguer
            pass
        self._fd = fd
        return self

    def attach(self, other: object) -> None:
        """Stop ``other`` (anything with ``stop()``, e.g. a ``heartbeat.Heartbeat``) when the lock is released."""
        self._attached.append(other)

    def release(self) -> None:
        """Drop the lock (closing the file drops it; the file stays, so no two lockers race on it),
        after stopping what was attached to it."""
        while self._attached:
            self._attached.pop().stop()
        if self._fd is not None:
            fd, self._fd = self._fd, None
            os.close(fd)

    def __enter__(self) -> "RunLock":
        return self.acquire()

    def __exit__(self, *exc: object) -> None:
        self.release()
