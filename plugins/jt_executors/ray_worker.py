"""What a Ray worker runs for ``executor=ray``: one item, with its evaluation folder shipped.

An evaluation (a ``toolkit.execution.evaluate.Job``) writes its files to ``ctx.workdir``, a folder
on the driver. A worker that cannot see that folder (no shared filesystem) gets the folder's
current contents packed with the item (so a checkpoint found there is resumed), works in a private
temporary folder and returns that folder packed with the result; the driver unpacks it into its
own ``ctx.workdir`` and logs it to the store from there. Workers never talk to the store.

``ship`` decides when that happens: ``always``; ``never`` (the folder is shared); ``auto`` (the
default): only when the worker does not see the driver's folder (its path holds the run id, so on
a worker that does not share the filesystem it does not exist).

A Ray system failure inside the item (a rollout actor it started died, or that actor's node) is
returned as ``Outcome.lost`` rather than raised, so the driver can retry the evaluation or report
it failed; an exception of the item's own code is raised as it is.
"""

from __future__ import annotations

import dataclasses
import io
import os
import shutil
import socket
import tarfile
import tempfile
from pathlib import Path
from typing import Any, Callable, Optional

SHIP_MODES = ("auto", "always", "never")


@dataclasses.dataclass
class Outcome:
    """What a worker returns for one item.

    Attributes:
        value: ``fn(item)`` (None when lost).
        files: the evaluation folder packed as an uncompressed tar, or None when not shipped.
        lost: why the item could not finish (a Ray system failure inside it); ``""`` when it did.
        host: the worker's host name and process id, for messages.
    """

    value: Any = None
    files: Optional[bytes] = None
    lost: str = ""
    host: str = ""


def _skipped(name: str) -> bool:
    """Files never shipped: atomic-write temporaries and lock files."""
    return ".tmp-" in name or name.endswith(".lock")


def pack(folder: Optional[Path]) -> Optional[bytes]:
    """Every file under ``folder`` as tar bytes; None for a missing or empty folder."""
    if folder is None or not Path(folder).is_dir():
        return None
    files = [p for p in sorted(Path(folder).rglob("*")) if p.is_file() and not _skipped(p.name)]
    if not files:
        return None
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w") as tar:
        for p in files:
            tar.add(p, arcname=str(p.relative_to(folder)), recursive=False)
    return buf.getvalue()


def unpack(data: Optional[bytes], folder: Path) -> list[str]:
    """Write the files of ``pack``'s bytes into ``folder`` (created); returns their names."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    if not data:
        return []
    with tarfile.open(fileobj=io.BytesIO(data), mode="r") as tar:
        names = [m.name for m in tar.getmembers() if m.isfile()]
        tar.extractall(folder, filter="data")
    return names


def workdir_of(item: Any) -> Optional[Path]:
    """The evaluation folder of ``item`` (its ``ctx.workdir``), or None for other work."""
    ctx = getattr(item, "ctx", None)
    wd = getattr(ctx, "workdir", None)
    return Path(wd) if wd is not None and dataclasses.is_dataclass(item) else None


def with_workdir(item: Any, folder: Path) -> Any:
    """A copy of ``item`` whose ``ctx.workdir`` is ``folder``."""
    return dataclasses.replace(item, ctx=dataclasses.replace(item.ctx, workdir=Path(folder)))


def _system_failure(exc: BaseException) -> bool:
    """A Ray failure of the machinery (a dead actor, worker or node), not of the item's code."""
    try:
        from ray import exceptions as rex
    except ImportError:  # pragma: no cover - only called on a Ray worker
        return False
    return isinstance(exc, rex.RayError) and not isinstance(exc, rex.RayTaskError)


def jt_evaluate(fn: Callable[[Any], Any], item: Any, files: Optional[bytes], ship: str) -> Outcome:
    """Run ``fn(item)`` on a worker, shipping the evaluation folder as ``ship`` says.

    The function's name is the worker's process title (``ray::jt_evaluate``) while it runs.

    Args:
        fn: a module-level function (``toolkit.execution.evaluate.run_job``).
        item: its argument; a dataclass with ``ctx.workdir`` has its folder shipped.
        files: the driver's folder packed (``pack``), or None.
        ship: ``auto``, ``always`` or ``never``.
    """
    host = f"{socket.gethostname()} pid {os.getpid()}"
    wd = workdir_of(item)
    local = wd is None or ship == "never" or (ship == "auto" and wd.is_dir())
    tmp = None if local else Path(tempfile.mkdtemp(prefix="jt-eval-"))
    try:
        if tmp is not None:
            unpack(files, tmp)
            item = with_workdir(item, tmp)
        try:
            value = fn(item)
        except Exception as e:  # noqa: BLE001 - only Ray's own failures are caught here
            if _system_failure(e):
                return Outcome(lost=f"{type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}", host=host)
            raise
        return Outcome(value=value, files=pack(tmp) if tmp is not None else None, host=host)
    finally:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
