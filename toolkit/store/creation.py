"""A new store's database, built where no signal can leave it half-built.

MLflow creates ``mlflow.db`` in place and then runs its schema migrations in it for about a second:
a Ctrl-C, SIGTERM or kill -9 then leaves a database every later run refuses (``table
_alembic_tmp_model_versions already exists``, ``duplicate column name`` ...). Here a new database
is made and migrated under another name in the store's folder (``mlflow.db.partial-<pid>``), and
renamed into place only when complete (``os.replace`` is atomic on one file system), so the store
either has no database yet or a whole one. A partial file left by a killed process is removed by
the next opening, and a database that an older jt left half-migrated (it never held a run) is
rebuilt; one that holds runs is never touched (the caller explains it in one line).

Callers hold the store's lock (``toolkit.store.tracking``) around every function here.
"""

from __future__ import annotations

import os
import sqlite3
from pathlib import Path
from typing import Callable

DB = "mlflow.db"
PARTIAL = DB + ".partial-"  #: a database being built: ``mlflow.db.partial-<pid>``


def needs_building(db: Path) -> bool:
    """No database yet: no file, or an empty one (SQLite's file made, nothing written)."""
    return not db.is_file() or db.stat().st_size == 0


def remove_partials(root: Path) -> list[Path]:
    """Remove the partial databases of processes that are gone (killed while building); those of a
    live process are left to it. Returns what was removed."""
    gone = []
    for path in root.glob(PARTIAL + "*"):
        pid = path.name[len(PARTIAL):].split("-")[0]
        if pid.isdigit() and _alive(int(pid)) and int(pid) != os.getpid():
            continue
        path.unlink(missing_ok=True)
        gone.append(path)
    return gone


def build(root: Path, migrate: Callable[[str], None]) -> None:
    """Make ``root/mlflow.db`` whole or not at all.

    Args:
        root: the store folder (exists).
        migrate: ``migrate(uri)`` creates and migrates MLflow's schema in the SQLite database at
            ``uri`` and releases every connection to it.
    """
    partial = root / f"{PARTIAL}{os.getpid()}"
    partial.unlink(missing_ok=True)
    try:
        migrate(f"sqlite:///{partial}")
        with open(partial, "rb+") as fh:  # on disk before it gets its name
            os.fsync(fh.fileno())
        os.replace(partial, root / DB)
    finally:
        partial.unlink(missing_ok=True)


def never_held_a_run(db: Path) -> bool:
    """True when ``db`` is an SQLite file with no run in it (a first run's store, interrupted while
    its schema was migrated); False when it holds runs or cannot be read as SQLite."""
    try:
        con = sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=30)
    except sqlite3.Error:
        return False
    try:
        tables = {r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        if "runs" not in tables:
            return True
        return con.execute("SELECT COUNT(*) FROM runs").fetchone()[0] == 0
    except sqlite3.Error:
        return False
    finally:
        con.close()


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
