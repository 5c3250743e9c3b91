"""Fault injection on real ``jt run`` processes: kill -9 at seeded random moments, SIGTERM, a resume of
a live run, two resumes at once, a full disk (``-m slow``: it mounts a tmpfs). After each, the
store must be consistent (one FINISHED outer run, each ``eval-NNNN`` FINISHED exactly once,
cut-off evaluations KILLED as ``eval-NNNN·interrupted``, nothing left RUNNING, no temp file) and
the resumed search must have measured what an uninterrupted run with the same seed measures.

Every store starts as a copy of one migrated ``mlflow.db`` (MLflow's migrations cost seconds).
"""

from __future__ import annotations

import json
import os
import random
import shutil
import signal
import socket
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import jt_env, store_query

SEED = 7
COMMON = ["task=quadratic", "search=random", "search.batch=2", "executor.workers=1", f"seed={SEED}"]
_REFERENCE: dict[int, list[tuple[float, float]]] = {}


@pytest.fixture(scope="module")
def template_db(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One migrated, empty ``mlflow.db``, copied into every test's store."""
    from toolkit.store.tracking import Store

    root = tmp_path_factory.mktemp("template") / "store"
    Store(root)
    return root / "mlflow.db"


def _new_store(template_db: Path, root: Path) -> Path:
    root.mkdir(parents=True, exist_ok=True)
    shutil.copy(template_db, root / "mlflow.db")
    return root


def _reference(budget: int, template_db: Path, tmp_path: Path) -> list[tuple[float, float]]:
    """``(value, noise0)`` of every evaluation of an uninterrupted run (in this process, cached)."""
    if budget not in _REFERENCE:
        from toolkit.config import compose
        from toolkit.execution.runner import run

        store = _new_store(template_db, tmp_path / f"reference{budget}")
        res = run(compose([*COMMON, f"search.budget={budget}", f"store={store}"]))
        _REFERENCE[budget] = [(e.metrics["value"], e.metrics["noise0"]) for e in res.evaluations]
    return _REFERENCE[budget]


def _jt(plugin_dir: Path, *args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "toolkit.cli", *args], env=jt_env(plugin_dir),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


_query = store_query


def _outer_ids(store: Path) -> list[str]:
    return [r[0] for r in _query(store, "select run_uuid from runs r where not exists (select 1 from tags t "
                                        "where t.run_uuid = r.run_uuid and t.key = 'mlflow.parentRunId')")]


def _wait(what: str, cond, timeout: float = 120, every: float = 0.05):  # noqa: ANN001
    deadline = time.time() + timeout
    while time.time() < deadline:
        got = cond()
        if got:
            return got
        time.sleep(every)
    raise AssertionError(f"timed out waiting for {what}")


def _owner(store: Path, rid: str) -> int:
    """The pid written in the run's lock file (0 if none yet)."""
    try:
        return int(json.loads((store / "work" / rid / "run.lock").read_text() or "{}").get("pid", 0))
    except (OSError, ValueError):
        return 0


def _finish(plugin_dir: Path, store: Path, rid: str) -> subprocess.CompletedProcess:
    p = subprocess.run([sys.executable, "-m", "toolkit.cli", "run", f"resume={rid}", f"store={store}"],
                       env=jt_env(plugin_dir), capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    return p


def _assert_consistent(store: Path, rid: str, reference: list[tuple[float, float]]) -> None:
    """One FINISHED outer run, each evaluation FINISHED once with the uninterrupted run's metrics,
    cut-off ones KILLED and renamed, nothing RUNNING, no temp file."""
    from toolkit.store import h5

    assert _outer_ids(store) == [rid]
    assert _query(store, "select status from runs where run_uuid = ?", rid) == [("FINISHED",)]
    assert _query(store, "select name from runs where status = 'RUNNING'") == []
    kids = _query(store, "select r.run_uuid, r.name, r.status from runs r join tags t on t.run_uuid = r.run_uuid "
                         "where t.key = 'mlflow.parentRunId' and t.value = ?", rid)
    finished = {name: uuid for uuid, name, status in kids if status == "FINISHED"}
    budget = len(reference)
    assert sorted(n for _, n, s in kids if s == "FINISHED") == [f"eval-{i:04d}" for i in range(budget)]
    assert all(s == "KILLED" and n.endswith("·interrupted") for _, n, s in kids if s != "FINISHED"), kids
    got = []
    for i in range(budget):
        m = dict(_query(store, "select key, value from latest_metrics where run_uuid = ? and key in "
                               "('value', 'noise0')", finished[f"eval-{i:04d}"]))
        got.append((m["value"], m["noise0"]))
    assert got == reference  # what an uninterrupted run with the same seed measured
    assert list(h5.read(store / "work" / rid / "search_history.h5")["index"]) == list(range(budget))
    assert [p for p in store.rglob("*") if ".tmp" in p.name] == []


def test_a_resume_of_a_live_run_is_refused_in_one_line(example_plugin, template_db, tmp_path):
    """A resume of a run that a live process drives: one line naming that process (pid, host), exit 2,
    the run untouched; the owner then finishes it with no evaluation twice."""
    store = _new_store(template_db, tmp_path / "store")
    proc = _jt(example_plugin, "run", *COMMON, "search.budget=4", "task.sleep=2.5", f"store={store}")
    rid = _wait("the run's row", lambda: _outer_ids(store))[0]
    _wait("the run's lock", lambda: _owner(store, rid) == proc.pid)
    refused = subprocess.run([sys.executable, "-m", "toolkit.cli", "run", f"resume={rid}", f"store={store}"],
                             env=jt_env(example_plugin), capture_output=True, text=True, timeout=300)
    assert proc.poll() is None, "the run ended before the second resume was tried; give it longer evaluations"
    assert refused.returncode == 2, refused.stderr
    line, = refused.stderr.strip().splitlines()
    assert line.startswith(f"jt: run {rid} is already being run by pid {proc.pid} on {socket.gethostname()}")
    assert "jt.resumed" not in dict(_query(store, "select key, value from tags where run_uuid = ?", rid))
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err
    _assert_consistent(store, rid, _reference(4, template_db, tmp_path))


def _take_over(plugin_dir: Path, store: Path, rid: str) -> subprocess.Popen:
    """``jt run resume=rid``, returned once it owns the run (or has ended)."""
    proc = _jt(plugin_dir, "run", f"resume={rid}", f"store={store}")
    _wait("the run's lock", lambda: _owner(store, rid) == proc.pid or proc.poll() is not None)
    return proc


def _status(store: Path, rid: str) -> str:
    return _query(store, "select status from runs where run_uuid = ?", rid)[0][0]


@pytest.mark.parametrize("kills", [1, pytest.param(4, marks=pytest.mark.slow)])
def test_kill9_sigterm_and_two_resumes_at_once_end_as_an_uninterrupted_run(example_plugin, template_db, tmp_path,
                                                                            kills):
    """Kill -9 the moment the run's row exists (its config was written before: it resumes), kill -9
    resumes at seeded random moments (evaluating, logging, saving the history, summarising), SIGTERM
    one, then start two resumes at once: one finishes the run, the other is refused in one line (or,
    second, finds it finished); the store ends as if nothing had happened."""
    rng = random.Random(1000 + kills)
    store = _new_store(template_db, tmp_path / "store")
    proc = _jt(example_plugin, "run", *COMMON, "search.budget=6", "task.sleep=0.3", f"store={store}")
    rid = _wait("the run's row", lambda: _outer_ids(store), every=0.002)[0]
    os.kill(proc.pid, signal.SIGKILL)
    proc.communicate()
    assert _status(store, rid) == "RUNNING"
    for _ in range(kills):
        proc = _take_over(example_plugin, store, rid)
        time.sleep(rng.uniform(0.0, 2.0))
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGKILL)
        _, err = proc.communicate()
        assert "cannot be resumed" not in err
    if _status(store, rid) != "FINISHED":
        proc = _take_over(example_plugin, store, rid)
        time.sleep(rng.uniform(0.0, 1.0))
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
        assert proc.returncode in (0, 130, -signal.SIGTERM), err  # 0: finished first; -15: after the run
        if "interrupted; continue it with" in err:
            assert proc.returncode == 130 and _status(store, rid) == "KILLED"
    if _status(store, rid) != "FINISHED":
        both = [_jt(example_plugin, "run", f"resume={rid}", f"store={store}") for _ in range(2)]
        outs = [(p.wait(timeout=300), p.communicate()[1]) for p in both]
        assert sorted(rc for rc, _ in outs) == [0, 2], outs
        (_, err), = [o for o in outs if o[0] == 2]
        line, = err.strip().splitlines()
        assert line.startswith(f"jt: run {rid} is already being run by pid ") or \
            line == f"jt: run {rid} already finished; nothing to resume", line
    _assert_consistent(store, rid, _reference(6, template_db, tmp_path))
    assert _query(store, "select value from params where run_uuid = ? and key = 'seed'", rid) == [(str(SEED),)]
    assert (store / "runs" / "quadratic" / rid / "artifacts" / "config.yaml").is_file()


@pytest.fixture()
def small_disk(tmp_path: Path):
    """A 48 MiB tmpfs mounted for the test (skipped where mounting is not allowed)."""
    where = tmp_path / "disk"
    where.mkdir()
    p = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=48m", "tmpfs", str(where)], capture_output=True,
                       text=True)
    if p.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here to fill a disk (needs root or CAP_SYS_ADMIN): "
                    f"{(p.stderr or p.stdout).strip()[:200]}")
    try:
        yield where
    finally:
        if subprocess.run(["umount", str(where)], capture_output=True).returncode != 0:
            subprocess.run(["umount", "-l", str(where)], capture_output=True)


def _fill(path: Path) -> None:
    """Write ``path`` until the disk is full."""
    block = b"\0" * (1 << 20)
    with open(path, "wb", buffering=0) as fh:
        try:
            while True:
                fh.write(block)
        except OSError:
            pass
    while True:  # the last partial megabyte too
        try:
            with open(path, "ab", buffering=0) as fh:
                fh.write(b"\0" * 4096)
        except OSError:
            return


def test_a_full_disk_is_told_apart_from_other_errors():
    """What a full disk raises: an OSError ENOSPC (copying an artifact), HDF5's OSError (errno in
    the text), SQLite's "database or disk is full" wrapped by MLflow, each maybe as a cause."""
    import errno

    from toolkit.execution.lifecycle import disk_full

    assert disk_full(OSError(errno.ENOSPC, "No space left on device", "/s/x.h5")) == \
        "No space left on device: /s/x.h5"
    assert disk_full(OSError("Unable to synchronously create file (file write failed: errno = 28, ...)"))
    try:
        try:
            raise sqlite3.OperationalError("database or disk is full")
        except sqlite3.OperationalError as inner:
            raise RuntimeError("(sqlite3.OperationalError) database or disk is full\n[SQL: INSERT ...]") from inner
    except RuntimeError as e:
        assert disk_full(e) == "(sqlite3.OperationalError) database or disk is full"
    assert disk_full(OSError(errno.EACCES, "Permission denied")) is None
    assert disk_full(ValueError("no such run")) is None


@pytest.mark.slow  # mounts a filesystem; two more jt processes (~20 s on 2 busy cores)
def test_a_full_disk_fails_in_one_line_and_resumes_once_freed(example_plugin, template_db, tmp_path, small_disk):
    """The disk fills while evaluating: one line (exit 2) that says how to resume, no temp file left;
    once space is freed the resume finishes it as if nothing had happened."""
    store = _new_store(template_db, small_disk / "store")
    proc = _jt(example_plugin, "run", *COMMON, "search.budget=4", "task.sleep=0.5", f"store={store}")
    rid = _wait("the run's row", lambda: _outer_ids(store))[0]
    _wait("a first evaluation", lambda: _query(store, "select 1 from runs where status = 'FINISHED'"))
    ballast = small_disk / "ballast"
    _fill(ballast)
    try:
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 2, err
    assert all(line.startswith("jt: ") for line in err.strip().splitlines()), err  # no traceback, no MLflow log
    last = err.strip().splitlines()[-1]
    assert last.startswith(f"jt: run {rid} stopped: no space left") and f"resume={rid}" in last, err
    assert [p for p in store.rglob("*") if ".tmp" in p.name] == []
    ballast.unlink()
    _finish(example_plugin, store, rid)
    _assert_consistent(store, rid, _reference(4, template_db, tmp_path))


def test_a_terminated_comparison_ends_killed_with_nothing_left_running(example_plugin, template_db, tmp_path):
    """SIGTERM to a real ``jt compare`` while two cells run in its pool: the comparison run ends
    KILLED and nothing is left RUNNING (the comparison and both cells used to stay RUNNING for ever:
    only ``jt run`` turned SIGTERM into Ctrl-C)."""
    store = _new_store(template_db, tmp_path / "store")
    proc = _jt(example_plugin, "compare", "task=quadratic", "executor.workers=2", "task.sleep=4",
               f"store={store}", "--vary", "task.centre=0.0,0.5")  # two cells at once, in a process pool
    try:
        _wait("both cells' runs", lambda: _query(store, "select count(*) from runs where status = 'RUNNING' "
                                                        "and name not like 'compare%'") == [(2,)])
        time.sleep(1.5)  # past each cell's opening (a SIGTERM there leaves a run resumable, as it was)
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    rows = dict(_query(store, "select name, status from runs"))
    compares = [s for n, s in rows.items() if n.startswith("compare")]
    assert compares == ["KILLED"], rows
    cells = [s for n, s in rows.items() if not n.startswith("compare")]
    assert len(cells) == 2 and set(cells) <= {"KILLED", "FINISHED"}, rows  # the pool's cells end, killed or done


def test_sigterm_at_seeded_moments_stops_at_a_safe_point(example_plugin, template_db, tmp_path):
    """SIGTERM at 20 seeded moments of a real run (opening, evaluating, logging, saving the history,
    summarising; issue 30): the handler only records the request and the run stops at its next safe
    point (``toolkit.execution.stopping``), so each ends with exit 130 and the run KILLED (or, sent
    after the end, exit 0 and FINISHED), never with an exception swallowed inside the handler or a
    store write cut halfway: nothing RUNNING, and a resume finishes it as an uninterrupted run would."""
    from toolkit.cli import _resume_config
    from toolkit.execution.runner import run

    rng = random.Random(2026)
    reference = _reference(4, template_db, tmp_path)
    outcomes = []
    for k in range(20):
        store = _new_store(template_db, tmp_path / f"s{k}")
        proc = _jt(example_plugin, "run", *COMMON, "search.budget=4", "task.sleep=0.2", f"store={store}")
        rid = _wait("the run's row", lambda: _outer_ids(store), every=0.002)[0]
        time.sleep(rng.uniform(0.0, 1.6))
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
        assert "Exception ignored" not in err and "internal error" not in err and "Traceback" not in err, err
        status = _status(store, rid)
        outcomes.append((proc.returncode, status))
        if proc.returncode == 0:
            assert status == "FINISHED", err
        else:
            assert proc.returncode == 130 and status == "KILLED", (proc.returncode, status, err)
            assert f"jt run resume={rid}" in err
            assert _query(store, "select name from runs where status = 'RUNNING'") == []
            run(_resume_config(rid, [f"store={store}"]))
        _assert_consistent(store, rid, reference)
    assert sum(rc == 130 for rc, _ in outcomes) >= 12, outcomes  # most signals arrived while it ran


def test_sigterm_while_pool_workers_evaluate_ends_them_at_once(example_plugin, template_db, tmp_path):
    """Two 30 s evaluations in the local executor's pool: SIGTERM stops the run within seconds (the
    driver checks for the request while it waits, and ends the workers instead of waiting for
    them), exit 130, the run and both evaluations KILLED."""
    store = _new_store(template_db, tmp_path / "store")
    proc = _jt(example_plugin, "run", "task=quadratic", "search=random", "search.batch=2", "search.budget=2",
               "executor.workers=2", "task.sleep=30", f"store={store}")
    rid = _wait("the run's row", lambda: _outer_ids(store))[0]
    _wait("both evaluations", lambda: len(_query(store, "select name from runs where status = 'RUNNING' and "
                                                      "name like 'eval-%'")) == 2)
    time.sleep(1.0)
    t0 = time.monotonic()
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert time.monotonic() - t0 < 15, "the run waited for its evaluations"
    assert proc.returncode == 130 and _status(store, rid) == "KILLED", err
    assert _query(store, "select name from runs where status = 'RUNNING'") == []


def test_ctrl_c_in_a_terminal_stops_the_run_and_its_pool_workers(example_plugin, template_db, tmp_path):
    """A terminal's Ctrl-C signals the whole process group (driver and pool workers): the run stops
    within seconds at its next safe point, exit 130, the run and both evaluations KILLED (resumable),
    and the driver says where it stops."""
    store = _new_store(template_db, tmp_path / "store")
    proc = subprocess.Popen([sys.executable, "-m", "toolkit.cli", "run", "task=quadratic", "search=random",
                             "search.batch=2", "search.budget=2", "executor.workers=2", "task.sleep=30",
                             f"store={store}"], env=jt_env(example_plugin), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,  # its own group, as a terminal's job
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        rid = _wait("the run's row", lambda: _outer_ids(store))[0]
        _wait("both evaluations", lambda: len(_query(store, "select name from runs where status = 'RUNNING' and "
                                                          "name like 'eval-%'")) == 2)
        time.sleep(1.0)
        t0 = time.monotonic()
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
    assert time.monotonic() - t0 < 15, "the run waited for its evaluations"
    assert proc.returncode == 130 and _status(store, rid) == "KILLED", err
    assert "stopping at the next safe point" in err and f"jt run resume={rid}" in err
    assert _query(store, "select name from runs where status = 'RUNNING'") == []


def test_closing_the_terminal_stops_the_run_at_a_safe_point(example_plugin, template_db, tmp_path):
    """SIGHUP to the whole group (a closed window, a dropped ssh session) with the terminal gone
    (the pipes closed: every write would fail): the run stops like after SIGTERM, exit 130, the
    run and its evaluations KILLED and resumable, the workers left to the driver."""
    store = _new_store(template_db, tmp_path / "store")
    proc = subprocess.Popen([sys.executable, "-m", "toolkit.cli", "run", "task=quadratic", "search=random",
                             "search.batch=2", "search.budget=2", "executor.workers=2", "task.sleep=30",
                             f"store={store}"], env=jt_env(example_plugin), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=_hangup_default)  # a suite started under nohup would pass SIG_IGN on
    try:
        rid = _wait("the run's row", lambda: _outer_ids(store))[0]
        _wait("both evaluations", lambda: len(_query(store, "select name from runs where status = 'RUNNING' and "
                                                          "name like 'eval-%'")) == 2)
        time.sleep(1.0)
        proc.stdout.close()
        proc.stderr.close()
        t0 = time.monotonic()
        os.killpg(proc.pid, signal.SIGHUP)
        proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert time.monotonic() - t0 < 15, "the run waited for its evaluations"
    assert proc.returncode == 130 and _status(store, rid) == "KILLED"
    assert _query(store, "select name from runs where status = 'RUNNING'") == []


def _hangup_default() -> None:
    """SIGHUP's default disposition in a child: the test is of a terminal closing, not of nohup's."""
    signal.signal(signal.SIGHUP, signal.SIG_DFL)


@pytest.fixture
def hangup_default():
    """SIGHUP at its default while a test runs (a suite started under nohup inherits SIG_IGN, which
    ``stopping.Terminate`` rightly leaves alone); the inherited disposition restored after."""
    inherited = signal.signal(signal.SIGHUP, signal.SIG_DFL)
    yield
    signal.signal(signal.SIGHUP, inherited)


def test_sighup_is_a_request_unless_it_is_ignored(hangup_default):
    from toolkit.execution import stopping

    with stopping.Terminate():
        saved = os.dup(1), os.dup(2)
        try:
            os.kill(os.getpid(), signal.SIGHUP)
            assert stopping.requested() == stopping.Terminate.REASON_HUP
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
    assert signal.getsignal(signal.SIGHUP) is signal.SIG_DFL
    old = signal.signal(signal.SIGHUP, signal.SIG_IGN)  # nohup
    try:
        with stopping.Terminate():
            assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGHUP, old)


def test_the_handler_only_records_the_request_and_a_second_one_raises():
    from toolkit.execution import stopping

    with stopping.Terminate():
        os.kill(os.getpid(), signal.SIGTERM)  # delivered here, in the main thread: nothing raised
        assert stopping.requested() == "terminated (SIGTERM)"
        with pytest.raises(KeyboardInterrupt, match="SIGTERM"):
            stopping.check()
        with pytest.raises(KeyboardInterrupt):
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.5)  # the second signal raises where the main thread is
    assert stopping.requested() is None  # cleared when the run's block ends


def test_ctrl_c_asks_for_a_safe_point_and_a_second_one_stops_at_once():
    """Python's own SIGINT handler raises wherever the main thread is (inside a weakref callback it
    is swallowed and the run goes on to FINISHED): while a run is open the first Ctrl-C is a
    request, as SIGTERM is; an ignored SIGINT (a background job) stays ignored."""
    from toolkit.execution import stopping

    old = signal.signal(signal.SIGINT, signal.default_int_handler)  # as in a terminal
    try:
        with stopping.Terminate():
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.1)  # nothing raised here
            assert stopping.requested() == "interrupted (Ctrl-C)"
            with pytest.raises(KeyboardInterrupt, match="Ctrl-C"):
                stopping.check()
            with pytest.raises(KeyboardInterrupt):
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.5)
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        with stopping.Terminate():
            assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.1)
            assert stopping.requested() is None
    finally:
        signal.signal(signal.SIGINT, old)


@pytest.mark.slow
def test_a_high_jump_search_stopped_mid_evaluation_resumes_bit_for_bit(template_db, tmp_path):
    """A real policy search (PPO evaluations, P-VAE-free smoke settings), SIGTERM in its second
    evaluation's training, resumed: every feature equals the uninterrupted run's exactly (issue 55;
    it differed in the 7th digit while bar contacts reordered PyBullet's contact pairs)."""
    from toolkit.store import h5

    args = ["run", "task=highjump", "search=bds", "experiment=smoke", "search.budget=2",
            "agent.total_samples=2048", "agent.checkpoint_every=3", "seed=0"]
    whole = _new_store(template_db, tmp_path / "whole")
    p = _jt(tmp_path, *args, f"store={whole}")
    assert p.wait(timeout=600) == 0, p.communicate()[1]
    cut = _new_store(template_db, tmp_path / "cut")
    p = _jt(tmp_path, *args, f"store={cut}")
    rid = _wait("the run's row", lambda: _outer_ids(cut), every=0.05)[0]
    _wait("the second evaluation", lambda: (cut / "work" / rid / "eval_0001" / "ppo.h5").is_file(), timeout=600)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=120)
    assert p.returncode == 130 and _status(cut, rid) == "KILLED", err
    p = _jt(tmp_path, "run", f"resume={rid}", f"store={cut}")
    assert p.wait(timeout=600) == 0, p.communicate()[1]
    a, b = (h5.read(next((s / "work").glob("*/search_history.h5"))) for s in (whole, cut))
    assert a["features"].shape == (2, 1)
    for key in ("x", "features", "objectives"):
        assert np.array_equal(a[key], b[key], equal_nan=True), key
    timing = [k for k in a["metrics"] if k.endswith("_s") or "per_s" in k or "wall" in k]  # wall time
    assert {"samples_per_s", "train_wall_s", "wall_collect_s"} <= set(timing) and len(a["metrics"]) > 15
    assert all(k == "samples_per_s" or k.startswith("wall_") or k == "train_wall_s" for k in timing), timing
    for key in sorted(set(a["metrics"]) - set(timing)):  # every other metric, ==
        assert np.array_equal(a["metrics"][key], b["metrics"][key], equal_nan=True), key
