"""How ``jt run`` opens, reopens and owns its outer run, so that a run is resumable at every moment.

A run is resumable from the moment its MLflow row exists: its config is written first, to
``<work>/_new/<token>.yaml``, and the row is created with the tag ``jt.config_staged=<token>``
(the tags are inserted with the row, in one transaction). Only then is the file moved to the
run's own ``<work>/<run_id>/config.yaml``, its params and the config artifact logged. A ``kill
-9`` anywhere in between leaves a RUNNING run whose config ``saved_config`` still finds; the
resume finishes the opening (``complete_opening``).

A run is driven by one process at a time: ``open_run`` takes the run's lock
(``toolkit.execution.lock``) before it changes anything, so a second ``resume=`` of a run that a
live process drives is refused in one line, and a dead owner (``kill -9``) blocks nothing. On a
server store, whose working folders are per machine, the owner also beats a heartbeat tag
(``toolkit.execution.heartbeat``) that a resume from another machine checks.
"""

from __future__ import annotations

import errno
import os
import uuid
from pathlib import Path
from typing import Any, Optional

from toolkit.errors import JtError
from toolkit.execution import describe
from toolkit.execution.heartbeat import Heartbeat, check_not_owned
from toolkit.execution.lock import RunLock
from toolkit.store import atomic
from toolkit.store.tracking import Store

STAGED_TAG = "jt.config_staged"
"""The outer run's tag naming its config written before the run existed (``<work>/_new/<token>.yaml``)."""
CONFIG_NAME = "config.yaml"


def _staged_path(store: Store, token: str) -> Path:
    return store.workdir("_new") / f"{token}.yaml"


def _remove_temp_files(workdir: Path) -> None:
    """Delete the ``*.tmp-<pid>`` files (atomic writes cut off by a kill) in a run's working folder:
    whoever wrote them is gone, since this process now holds the run's lock."""
    for p in workdir.rglob("*.tmp-*"):
        if p.is_file():
            p.unlink(missing_ok=True)


def saved_config(store: Store, run_id: str, run: Any = None) -> Optional[Path]:
    """The file holding run ``run_id``'s config: ``<workdir>/config.yaml``, else the one written
    before the run existed (a run killed before it moved it), else None."""
    path = store.workdir(run_id) / CONFIG_NAME
    if path.is_file():
        return path
    run = run if run is not None else store.get_run(run_id)
    token = run.data.tags.get(STAGED_TAG)
    if token and "/" not in token and _staged_path(store, token).is_file():
        return _staged_path(store, token)
    return None


def complete_opening(store: Store, run_id: str, cfg: Any, run: Any = None) -> None:
    """Whatever opening a run left undone: its config moved into its working folder, its params
    and its ``config.yaml`` artifact logged (for a new run, all of it; after a ``kill -9``, the rest).

    Args:
        store: the store.
        run_id: the outer run.
        cfg: its config (written when no saved one is found).
        run: the run as just read, or None for a run created a moment ago (nothing logged yet).
    """
    from omegaconf import OmegaConf

    from toolkit.config import flatten, to_yaml

    dst = store.workdir(run_id) / CONFIG_NAME
    if not dst.is_file():
        src = saved_config(store, run_id, run) if run is not None else None
        if src is not None:
            os.replace(src, dst)
        else:
            atomic.write_text(dst, to_yaml(cfg))
    if run is None:  # a new run: everything, as composed
        store.log_params(run_id, flatten(cfg))
        store.log_artifact(run_id, dst)
        return
    missing = {k: v for k, v in flatten(OmegaConf.load(dst)).items() if k not in run.data.params}
    if missing:
        store.log_params(run_id, missing)
    if not any(f.path == CONFIG_NAME for f in store.client.list_artifacts(run_id)):
        store.log_artifact(run_id, dst)


def open_run(store: Store, cfg: Any, experiment: str, command: str, task_cls: Any,
             nested: bool) -> tuple[str, bool, RunLock]:
    """Start a new outer run, or reopen ``cfg.resume``, owned by this process.

    Args:
        store: the store.
        cfg: the run's config (``cfg.resume`` set: reopen that run).
        experiment: the experiment (the task's name).
        command: the command that reproduces the run, for its description.
        task_cls: the task's class, for the experiment's description.
        nested: whether evaluations are nested runs, for the run's description.

    Returns:
        ``(run_id, resumed, lock)``; release the lock when the run ends.

    Raises:
        JtError: the run is finished, or another live process drives it.
    """
    from toolkit.config import to_yaml

    if cfg.resume:
        rid = str(cfg.resume)
        run = store.get_run(rid)
        if run.info.status == "FINISHED":
            raise JtError(f"run {rid} already finished; nothing to resume")
        check_not_owned(store, run)  # another machine's live driver (server stores)
        lock = RunLock(store.workdir(rid), rid).acquire(str(store.root))
        try:
            run = store.get_run(rid)  # the owner that just let go may have finished it
            if run.info.status == "FINISHED":
                raise JtError(f"run {rid} already finished; nothing to resume")
            check_not_owned(store, run)
            beat = Heartbeat(store, rid).start()
            lock.attach(beat)
            beat.confirm()  # two hosts resuming at once: the last to write jt.owner goes on
            _remove_temp_files(store.workdir(rid))
            complete_opening(store, rid, cfg, run)
            store.client.update_run(rid, status="RUNNING")
            store.set_tags(rid, {"jt.resumed": "true"})
        except BaseException as e:
            lock.release()
            _raise_if_disk_full(e, store, rid)
            raise
        return rid, True, lock
    describe.ensure_experiment(store, experiment, task_cls)
    token = uuid.uuid4().hex
    atomic.write_text(_staged_path(store, token), to_yaml(cfg))  # before the row: resumable at once
    tags = {
        **describe.provenance_tags(command),
        "jt.seed": str(cfg.seed),
        "jt.task": str(cfg.task.name),
        "jt.search": str(cfg.search.name),
        STAGED_TAG: token,
        describe.NOTE: describe.outer(cfg, command, nested=nested),
    }
    name = cfg.get("run_name") or store.unique_run_name(
        experiment, f"{cfg.task.name}·{cfg.search.name}·seed{cfg.seed}")  # what it is, never a collision
    try:
        run_id = store.start_run(experiment, run_name=name, tags=tags)
    except Exception:  # the insert failed, so no row names the file (an interrupt may come after it: kept)
        _staged_path(store, token).unlink(missing_ok=True)
        raise
    lock = None
    try:  # from here the row exists: every failure must say how to resume it
        lock = RunLock(store.workdir(run_id), run_id).acquire(str(store.root))  # a faster resume: refused here
        lock.attach(Heartbeat(store, run_id).start())
        os.replace(_staged_path(store, token), store.workdir(run_id) / CONFIG_NAME)
        complete_opening(store, run_id, cfg)
    except BaseException as e:
        if lock is not None:
            lock.release()
        _raise_if_disk_full(e, store, run_id)
        raise
    _sweep_staged(store)
    return run_id, False, lock


#: staged configs older than this (s) that no run names are the leftovers of a kill before the row
STALE_STAGED_S = 3600.0


def _sweep_staged(store: Store) -> None:
    """Remove staged configs (and their temp files) older than ``STALE_STAGED_S``: a process killed
    between staging its config and creating its row left them, and no run will ever read them."""
    import time

    folder = _staged_path(store, "x").parent
    now = time.time()
    for f in folder.glob("*"):
        try:
            if not f.is_file() or now - f.stat().st_mtime <= STALE_STAGED_S:
                continue
            if f.suffix == ".yaml" and _named_by_a_run(store, f.stem):
                continue  # its run was killed before it moved the file: a resume still needs it
            f.unlink()
        except OSError:  # another process removed or moved it first
            continue


def _named_by_a_run(store: Store, token: str) -> bool:
    """Whether a run's ``jt.config_staged`` tag names the staged config ``token``."""
    ids = [e.experiment_id for e in store.client.search_experiments()]
    return bool(ids) and bool(store.client.search_runs(
        ids, filter_string=f"tags.`{STAGED_TAG}` = '{token}'", max_results=1))


def close_stale_children(store: Store, run_id: str, experiment: str, recorded: set[int]) -> None:
    """Evaluations the interruption cut off (still RUNNING, or FINISHED but not yet in the saved
    history): KILLED and renamed ``eval-NNNN·interrupted``, so the re-evaluation that follows is the
    one ``eval-NNNN`` and no two runs share a name."""
    runs = store.client.search_runs(
        [store.experiment_id(experiment)],
        filter_string=f"tags.mlflow.parentRunId = '{run_id}' and attributes.status != 'KILLED'",
    )
    for r in runs:
        idx = r.data.tags.get("jt.eval_index")
        unsaved = r.info.status == "FINISHED" and idx is not None and int(idx) not in recorded
        if r.info.status == "RUNNING" or unsaved:
            store.set_tags(r.info.run_id, {"mlflow.runName": f"{r.info.run_name}·interrupted"})
            store.end_run(r.info.run_id, "KILLED", "interrupted; re-evaluated when the parent resumed")


_FULL = ("no space left on device", "disk is full", "errno = 28", "disk quota exceeded")


def disk_full(exc: BaseException) -> Optional[str]:
    """The first line of the error in ``exc``'s chain that says a disk is full, else None
    (``OSError`` ENOSPC/EDQUOT, SQLite's "database or disk is full", HDF5's "errno = 28")."""
    seen: set[int] = set()
    e: Optional[BaseException] = exc
    while e is not None and id(e) not in seen:
        seen.add(id(e))
        if isinstance(e, OSError) and e.errno in (errno.ENOSPC, errno.EDQUOT):
            return os.strerror(e.errno) + (f": {e.filename}" if e.filename else "")
        if any(s in str(e).lower() for s in _FULL):
            return (str(e).strip().splitlines() or [type(e).__name__])[0][:200]
        e = e.__cause__ or e.__context__
    return None


def stopped_by_full_disk(run_id: str, store: Store, detail: str) -> JtError:
    """The one line for a run a full disk stopped (it stays resumable)."""
    return JtError(f"run {run_id} stopped: no space left on a disk it writes to ({detail}); free some, "
                   f"then continue it with: jt run resume={run_id} store={store.root}")


def _raise_if_disk_full(exc: BaseException, store: Store, run_id: str) -> None:
    detail = disk_full(exc) if isinstance(exc, Exception) else None
    if detail:
        raise stopped_by_full_disk(run_id, store, detail) from exc
