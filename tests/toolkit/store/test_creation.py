"""A new store survives any signal while it is created (issue 55): the database is migrated under
another name and renamed into place whole; a store an older jt left half-migrated is rebuilt.

Real MLflow, real SQLite, real ``jt run`` processes signalled at seeded moments.
"""

from __future__ import annotations

import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from toolkit.errors import JtError
from toolkit.store import creation
from toolkit.store.tracking import Store

#: what an older jt did: MLflow creates and migrates mlflow.db in place
IN_PLACE = "import sys\nfrom mlflow.tracking import MlflowClient\n" \
           "MlflowClient(tracking_uri=f'sqlite:///{sys.argv[1]}').search_experiments(max_results=1)\n"


def _first_file(root: Path, proc: subprocess.Popen, pattern: str = "mlflow.db*", limit: float = 60.0) -> None:
    t0 = time.monotonic()
    while not list(root.glob(pattern)) and proc.poll() is None and time.monotonic() - t0 < limit:
        time.sleep(0.005)


def _run(store: Path, **kw) -> subprocess.Popen:
    return subprocess.Popen(["jt", "run", "task=zdt1", "experiment=smoke", f"store={store}"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, **kw)


def test_a_signal_while_a_store_is_created_never_leaves_it_broken(tmp_path):
    """Ctrl-C, SIGTERM or kill -9 at seeded moments of a first run's store creation (the first
    second after a database file appears), then a run on the same store: it finishes (5 of 11
    such signals used to leave a database every later run refused)."""
    rng = np.random.default_rng(55)
    for k, sig in enumerate((signal.SIGKILL, signal.SIGTERM, signal.SIGINT)):
        store = tmp_path / f"s{k}"
        store.mkdir()
        proc = _run(store)
        _first_file(store, proc)
        time.sleep(float(rng.uniform(0.0, 0.8)))
        proc.send_signal(sig)
        proc.communicate(timeout=120)
        again = _run(store)
        _, err = again.communicate(timeout=300)
        assert again.returncode == 0, (sig, err[-2000:])
        assert not list(store.glob(creation.PARTIAL + "*")), sorted(p.name for p in store.iterdir())
        runs = Store(store).client.search_runs([e.experiment_id for e in Store(store).client.search_experiments()])
        assert any(r.info.status == "FINISHED" for r in runs)


def _half_migrated_in_place(db: Path) -> None:
    """Kill MLflow's in-place creation (an older jt's) at growing moments until the database it
    leaves cannot be opened by MLflow."""
    for delay in np.arange(0.05, 3.0, 0.1):
        db.unlink(missing_ok=True)
        proc = subprocess.Popen([sys.executable, "-c", IN_PLACE, str(db)], stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
        _first_file(db.parent, proc, db.name)
        time.sleep(float(delay))
        proc.kill()
        proc.wait()
        check = subprocess.run([sys.executable, "-c", IN_PLACE, str(db)], capture_output=True, timeout=120)
        if check.returncode != 0:
            return
        db.unlink()
    pytest.fail("no kill moment left a broken database")  # pragma: no cover


def test_a_store_an_older_jt_left_half_migrated_is_rebuilt(tmp_path):
    root = tmp_path / "old"
    root.mkdir()
    _half_migrated_in_place(root / "mlflow.db")
    assert creation.never_held_a_run(root / "mlflow.db")
    store = Store(root)  # rebuilt: it never held a run
    run_id = store.start_run("e", "r")
    assert store.get_run(run_id).info.status == "RUNNING"
    assert store.client.get_experiment("0").artifact_location == str(root.resolve() / "runs" / "Default")


def test_a_database_that_holds_runs_is_never_rebuilt(tmp_path):
    """A database jt cannot open but that holds a run is explained in one line, never replaced."""
    root = tmp_path / "held"
    root.mkdir()
    db = root / "mlflow.db"
    con = sqlite3.connect(db)
    con.execute("CREATE TABLE runs (run_uuid TEXT)")
    con.execute("INSERT INTO runs VALUES ('abc')")
    con.execute("CREATE TABLE alembic_version (version_num TEXT)")
    con.execute("INSERT INTO alembic_version VALUES ('no_such_revision')")
    con.commit()
    con.close()
    assert not creation.never_held_a_run(db)
    with pytest.raises(JtError) as e:
        Store(root)
    assert "not a usable MLflow database" in str(e.value) and "move it away" in str(e.value)
    con = sqlite3.connect(db)
    assert con.execute("SELECT run_uuid FROM runs").fetchall() == [("abc",)]  # still there, not rebuilt
    con.close()


def test_build_leaves_no_database_when_the_migration_fails(tmp_path):
    def fails(uri: str) -> None:
        Path(uri[len("sqlite:///"):]).write_bytes(b"half")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        creation.build(tmp_path, fails)
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_partials_of_dead_processes_go_and_a_live_ones_stays(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"])
    try:
        (tmp_path / f"{creation.PARTIAL}{dead}").write_bytes(b"x")
        (tmp_path / f"{creation.PARTIAL}{live.pid}").write_bytes(b"x")
        gone = creation.remove_partials(tmp_path)
        assert [p.name for p in gone] == [f"{creation.PARTIAL}{dead}"]
        assert (tmp_path / f"{creation.PARTIAL}{live.pid}").exists()
    finally:
        live.kill()
        live.wait()


def test_a_store_path_the_file_system_cannot_hold_is_one_line(tmp_path):
    """A 300-character folder name, or a path with no room for the files under it, was an
    internal error (OSError: File name too long); now one line, nothing made."""
    for root in (tmp_path / ("a" * 300), tmp_path.joinpath(*["b" * 200] * 20)):
        with pytest.raises(JtError, match="give a shorter store="):
            Store(root)
    assert sorted(tmp_path.iterdir()) == []
