"""executor=local: the process pool (and the in-process path for workers=1), through the shipped
contract suite (``toolkit.testing.executor``), as a third-party executor's tests use it; and no
pool worker or actor outliving a driver killed with ``kill -9``."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from jt_executors.local import LocalExecutor
from toolkit.testing.executor import Counter, ExecutorContract


def _interrupted(x: int) -> int:
    """A pool task that gets a Ctrl-C (SIGINT) while it runs, then returns ``x``."""
    os.kill(os.getpid(), signal.SIGINT)
    time.sleep(0.1)
    return x


class TestLocalPool(ExecutorContract):
    executor_cls, entry, cfg = LocalExecutor, "local", {"name": "local", "workers": 2}

    def test_actors_live_in_other_processes(self, executor):
        group = executor.actors(Counter, [(0,), (0,)])
        try:
            pids = group.call("pid")
        finally:
            group.close()
        assert len(set(pids)) == 2 and os.getpid() not in pids

    def test_a_ctrl_c_sent_to_the_workers_leaves_them_working(self, executor):
        """A terminal's Ctrl-C signals the whole process group; the driver decides when to stop,
        so actors and pool workers ignore it (a worker killed mid-call made a run FAILED)."""
        group = executor.actors(Counter, [(0,), (0,)])
        try:
            pids = group.call("pid")
            for pid in pids:
                os.kill(pid, signal.SIGINT)
            time.sleep(0.3)
            assert group.call("add", [(1,), (2,)]) == [1, 2]
        finally:
            group.close()
        assert executor.map(_interrupted, [1, 2, 3]) == [1, 2, 3]  # pool workers too


class TestLocalInline(ExecutorContract):
    executor_cls, entry, cfg = LocalExecutor, "local", {"name": "local", "workers": 1}

    def test_everything_runs_in_this_process(self, executor):
        group = executor.actors(Counter, [(0,)])
        try:
            assert group.call("pid") == [os.getpid()]
        finally:
            group.close()
        assert executor.n_workers == 1


def test_workers_zero_means_one_per_core():
    assert LocalExecutor({"name": "local"}).n_workers == (os.cpu_count() or 1)


@pytest.mark.parametrize("workers", [1, 2])
def test_a_typed_config_instance_works_too(workers):
    with LocalExecutor(LocalExecutor.Config(workers=workers)) as ex:
        assert ex.n_workers == workers and ex.map(abs, [-1, -2, -3]) == [1, 2, 3]


# ---------------------------------------------------------------------------- kill -9 of the driver
linux_proc = pytest.mark.skipif(not Path("/proc/self/stat").is_file(), reason="reads /proc (Linux)")


def _ppid(pid: int) -> int | None:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    fields = stat.rsplit(")", 1)[1].split()  # after "(comm)": state, ppid, ...
    return int(fields[1]) if fields[0] != "Z" else None  # a zombie has ended


def _descendants(pid: int) -> set[int]:
    """Every live process under ``pid`` (from /proc)."""
    parents = {}
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            ppid = _ppid(int(d.name))
            if ppid is not None:
                parents[int(d.name)] = ppid
    out, frontier = set(), {pid}
    while frontier:
        frontier = {p for p, pp in parents.items() if pp in frontier and p not in out}
        out |= frontier
    return out


def _cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().decode(errors="replace")
    except OSError:
        return ""


def _alive(pids: set[int]) -> set[int]:
    return {p for p in pids if _ppid(p) is not None}


def _kill9_leaves_no_worker(proc: subprocess.Popen, n_workers: int, ready_s: float = 120.0) -> set[int]:
    """Wait until ``proc`` has ``n_workers`` worker processes, kill -9 it; the pids still alive 10 s
    later (the workers it had)."""
    deadline, workers = time.monotonic() + ready_s, set()
    while time.monotonic() < deadline and proc.poll() is None:
        workers = {p for p in _descendants(proc.pid) if "multiprocessing.spawn" in _cmdline(p)}
        if len(workers) >= n_workers:
            break
        time.sleep(0.2)
    assert proc.poll() is None and len(workers) >= n_workers, (workers, proc.poll())
    everything = _descendants(proc.pid)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)
    deadline = time.monotonic() + 10
    while _alive(everything) and time.monotonic() < deadline:
        time.sleep(0.1)
    left = _alive(everything)
    for p in left:  # do not leave them to the next test
        os.kill(p, signal.SIGKILL)
    return left


def _assert_kill9_leaves_no_worker(cmd: list, **popen) -> None:
    """Start ``cmd``, wait for its two workers, SIGKILL it: none of its processes may survive."""
    proc = subprocess.Popen(cmd, **popen)
    try:
        assert _kill9_leaves_no_worker(proc, 2) == set()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


@linux_proc
def test_kill9_of_a_jt_run_leaves_no_pool_worker(example_plugin_dir, tmp_path):
    """A real ``jt run ... executor.workers=2`` (evaluations of 30 s, so both pool workers are busy)
    is killed with SIGKILL: every process it started is gone within 10 s."""
    from tests.conftest import jt_env

    args = ["task=quadratic", "task.sleep=30", "search=random", "search.budget=4", "search.batch=2",
            "executor=local", "executor.workers=2", f"store={tmp_path / 'store'}"]
    _assert_kill9_leaves_no_worker([sys.executable, "-m", "toolkit.cli", "run", *args], env=jt_env(example_plugin_dir),
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=tmp_path)


ACTORS_DRIVER = """
import time
from jt_executors.local import LocalExecutor
LocalExecutor({"name": "local", "workers": 2}).actors(time.sleep, [(600,), (600,)])
"""


@linux_proc
def test_kill9_of_a_driver_leaves_no_actor(tmp_path):
    """Two actor processes of ``executor=local``, busy (building their object for 10 minutes, so
    not reading their pipe), end when their driver is killed with SIGKILL."""
    _assert_kill9_leaves_no_worker([sys.executable, "-c", ACTORS_DRIVER], cwd=tmp_path,
                                   env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})


def test_the_watchdog_alone_ends_an_orphan(tmp_path):
    """Without PR_SET_PDEATHSIG (other systems) the watchdog thread ends a worker whose parent
    died: a child armed with the watchdog only outlives its parent by at most about a second."""
    script = tmp_path / "w.py"
    script.write_text(
        "import os, sys, time\n"
        "from jt_executors import local\n"
        "if sys.argv[1] == 'parent':\n"
        "    import subprocess\n"
        "    child = subprocess.Popen([sys.executable, __file__, 'child', str(os.getpid())], stdout=subprocess.PIPE)\n"
        "    assert child.stdout.readline().strip() == b'armed'\n"  # the parent dies only once the guard runs
        "    print(child.pid, flush=True)\n"
        "    os._exit(0)\n"
        "local._die_with_parent(int(sys.argv[2]), pdeathsig=False)\n"
        "print('armed', flush=True)\n"
        "time.sleep(600)\n")
    proc = subprocess.run([sys.executable, str(script), "parent"], capture_output=True, text=True, timeout=60,
                          env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    child = int(proc.stdout.split()[0])
    deadline = time.monotonic() + 10
    while _ppid(child) is not None and time.monotonic() < deadline:
        time.sleep(0.1)
    alive = _ppid(child) is not None
    if alive:
        os.kill(child, signal.SIGKILL)
    assert not alive
