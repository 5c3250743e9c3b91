"""Atomic file writes: a temp file next to the target, fsynced, then renamed over it.

Every file jt writes whole (HDF5 artifacts, checkpoints, configs, generated URDFs) goes through
``atomic_write``, so a kill or an exception never leaves a truncated file where a reader looks:
the data goes to ``<name>.tmp-<pid>`` in the target's folder (the same file system, so
``os.replace`` is atomic), is fsynced, and only then replaces the target. The ``.tmp-`` infix is
what the rest of jt recognises as a write cut off by a kill (``toolkit.execution.lifecycle`` deletes
such files on resume, the store and the Ray worker never upload them).
"""

from __future__ import annotations

import os
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator


def temp_path(path: str | os.PathLike) -> Path:
    """The temp file ``atomic_write`` writes ``path`` through: ``<name>.tmp-<pid>`` next to it."""
    path = Path(path)
    return path.with_name(f"{path.name}.tmp-{os.getpid()}")


@contextmanager
def atomic_write(path: str | os.PathLike) -> Iterator[Path]:
    """Write a file atomically: the body writes the yielded temp path, which replaces ``path`` on exit.

    The body must close the temp file before it ends. On a normal exit the temp file is fsynced
    and renamed onto ``path`` (``os.replace``: a reader sees the old file or the new one, never
    half of one). If the body raises, the temp file is deleted, ``path`` is left as it was, and the
    exception propagates.

    Example::

        with atomic_write(target) as tmp:
            with h5py.File(tmp, "w") as f:
                ...

    Args:
        path: the target file; its parent folders are created.

    Yields:
        The temp path to write: ``<name>.tmp-<pid>`` in the target's folder.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = temp_path(path)
    try:
        yield tmp
        with open(tmp, "rb") as fh:  # on disk before the rename
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def write_text(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` to ``path`` atomically (``atomic_write``); returns ``path`` as a ``Path``."""
    path = Path(path)
    with atomic_write(path) as tmp:
        tmp.write_text(text)
    return path
