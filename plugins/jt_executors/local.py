"""``executor=local``: a process pool on this machine (the default)."""

from __future__ import annotations

import dataclasses
import multiprocessing as mp
import os
import signal
import sys
import threading
import time
import traceback
from typing import Any, Callable, Iterator, Optional, Sequence

from toolkit.execution import stopping
from toolkit.execution.actors import InlineActors
from toolkit.interfaces import ActorGroup, Executor


def _limit_threads() -> None:
    """One BLAS/torch thread per worker: the pool provides the parallelism."""
    for var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS", "NUMBA_NUM_THREADS"):
        os.environ[var] = "1"


#: seconds between two looks of the watchdog thread at this worker's parent
WATCHDOG_PERIOD_S = 0.5


def _arm_pdeathsig() -> bool:
    """Ask Linux to SIGKILL this process when its parent ends (``prctl(PR_SET_PDEATHSIG)``).

    Returns:
        True when armed (Linux with a C library that has ``prctl``), False elsewhere.
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        pr_set_pdeathsig = 1
        return libc.prctl(pr_set_pdeathsig, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _watch_parent(ppid: int, period: float) -> None:
    """Exit this process as soon as its parent is no longer ``ppid`` (the parent died and the
    worker was re-parented): the portable fallback of ``_arm_pdeathsig``."""
    while True:
        time.sleep(period)
        if os.getppid() != ppid:
            os._exit(1)


def _die_with_parent(parent_pid: Optional[int], pdeathsig: bool) -> None:
    """Make this worker process end when the process that started it ends, even by ``kill -9``.

    A driver killed by SIGKILL runs no clean-up, and a pool worker or actor blocked on its pipe
    would otherwise live on under init, holding a core and its memory. Two mechanisms: on Linux
    the kernel SIGKILLs the worker when its parent dies (``PR_SET_PDEATHSIG``); everywhere a
    daemon thread polls ``os.getppid()`` every ``WATCHDOG_PERIOD_S`` seconds and exits the worker
    when it changes (a worker blocked in C code that holds the GIL is only caught by the first).

    Args:
        parent_pid: the pid of the process expected to be this worker's parent (the driver for the
            ``spawn`` and ``fork`` start methods); if the worker's parent is already another
            process, the driver died before this ran and the worker exits now. None: not known
            (``forkserver``: the parent is the fork server, which itself exits with the driver).
        pdeathsig: arm ``PR_SET_PDEATHSIG``. Linux sends it when the parent *thread* that started
            the worker ends, so the caller passes True only when that thread is the main thread.
    """
    if pdeathsig:
        _arm_pdeathsig()
    ppid = os.getppid()
    if parent_pid is not None and ppid != parent_pid:
        os._exit(1)  # orphaned before the guard was armed
    threading.Thread(target=_watch_parent, args=(ppid, WATCHDOG_PERIOD_S), name="jt-parent-watchdog",
                     daemon=True).start()


def _ignore_ctrl_c() -> None:
    """A terminal's Ctrl-C, and its hang-up when the window closes, reach every process of its
    group: a worker ignores them and the driver decides (it stops the run at its next safe point
    and ends the workers, ``toolkit.execution.stopping``); a worker killed by one mid-call would
    turn a KILLED, resumable run into a FAILED one."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGHUP, signal.SIG_IGN)


def _worker_init(parent_pid: Optional[int], pdeathsig: bool) -> None:
    """Pool worker initializer: die with the driver, ignore Ctrl-C, one BLAS/torch thread, no
    native banners."""
    from toolkit.quiet import preload_quietly

    _die_with_parent(parent_pid, pdeathsig)
    _ignore_ctrl_c()
    _limit_threads()
    preload_quietly()


def _actor_main(conn: Any, factory: Callable[..., Any], args: tuple, parent_pid: Optional[int] = None,
                pdeathsig: bool = False) -> None:
    from toolkit.quiet import preload_quietly

    _die_with_parent(parent_pid, pdeathsig)
    _ignore_ctrl_c()
    _limit_threads()
    preload_quietly()
    try:
        obj = factory(*args)
        conn.send(("ok", None))
    except BaseException as e:  # report construction errors to the parent
        conn.send(("error", f"{type(e).__name__}: {e}\n{traceback.format_exc()}"))
        return
    while True:
        msg = conn.recv()
        if msg is None:
            break
        method, margs = msg
        try:
            conn.send(("ok", getattr(obj, method)(*margs)))
        except BaseException as e:
            conn.send(("error", f"{type(e).__name__}: {e}\n{traceback.format_exc()}"))
    close = getattr(obj, "close", None)
    if callable(close):
        close()


class WorkerError(RuntimeError):
    """An exception raised inside a worker process, with the worker's traceback."""



def _guard_args(method: str) -> tuple[Optional[int], bool]:
    """``(parent_pid, pdeathsig)`` for ``_die_with_parent`` of a worker started now, from this
    thread, with start method ``method``."""
    parent = None if method == "forkserver" else os.getpid()
    return parent, threading.current_thread() is threading.main_thread()


class _ProcessActors(ActorGroup):
    def __init__(self, ctx: Any, factory: Callable[..., Any], args: Sequence[tuple]) -> None:
        self._conns, self._procs = [], []
        guard = _guard_args(ctx.get_start_method())
        for a in args:
            parent, child = ctx.Pipe()
            p = ctx.Process(target=_actor_main, args=(child, factory, a, *guard), daemon=True)
            p.start()
            self._conns.append(parent)
            self._procs.append(p)
        self.size = len(self._procs)
        self._gather()

    def _gather(self) -> list[Any]:
        out = []
        for c in self._conns:
            status, value = c.recv()
            if status == "error":
                self.close()
                raise WorkerError(value)
            out.append(value)
        return out

    def call(self, method: str, args: Sequence[tuple] | None = None) -> list[Any]:
        args = args if args is not None else [()] * self.size
        for c, a in zip(self._conns, args):
            c.send((method, tuple(a)))
        return self._gather()

    def close(self) -> None:
        for c in self._conns:
            try:
                c.send(None)
            except (BrokenPipeError, OSError):
                pass
        for p in self._procs:
            p.join(timeout=5)
            if p.is_alive():
                p.terminate()
        self._conns, self._procs = [], []


class LocalExecutor(Executor):
    """Process pool on this machine; one worker per core by default.

    Pool workers and actors end with the process that started them, even when it is killed with
    ``kill -9`` (``_die_with_parent``): no orphan keeps a core after its driver is gone.
    """

    @dataclasses.dataclass
    class Config:
        name: str = "local"
        workers: int = 0
        """Worker processes; 0 means one per core. 1 runs everything in this process."""
        start_method: str = "spawn"
        """multiprocessing start method: spawn (safe with torch/pybullet), forkserver or fork."""

        def check(self) -> None:
            """workers >= 0 and a known start method (one ``JtError`` line, at composition)."""
            from toolkit.schema import require

            require(self.workers >= 0, "executor.workers", self.workers, "a count of workers >= 0 (0: one per core)")
            require(self.start_method in ("spawn", "forkserver", "fork"), "executor.start_method",
                    self.start_method, "spawn, forkserver or fork")

    def __init__(self, cfg: Any = None) -> None:
        from toolkit.config import config_of

        super().__init__(cfg)
        params = config_of(self.Config, cfg, "executor=local")  # a dict, a group node or a Config
        workers = int(params.workers or 0)
        self._workers = workers if workers > 0 else (os.cpu_count() or 1)
        self._method = str(params.start_method)
        self._pool: Optional[Any] = None
        self._pool_pdeathsig = False
        self._manager: Optional[Any] = None

    @property
    def n_workers(self) -> int:
        return self._workers

    def _context(self) -> Any:
        return mp.get_context(self._method)

    def imap(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> Iterator[tuple[int, Any]]:
        if self.runs_inline(len(items)):
            for i, x in enumerate(items):
                yield i, fn(x)
            return
        from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

        guard = _guard_args(self._method)
        if self._pool is not None and self._pool_pdeathsig and not guard[1]:
            # workers may be started by this thread now, and their PDEATHSIG would fire when it ends
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
        if self._pool is None:
            self._pool = ProcessPoolExecutor(
                max_workers=self._workers, mp_context=self._context(), initializer=_worker_init, initargs=guard
            )
            self._pool_pdeathsig = guard[1]
        futures = {self._pool.submit(fn, x): i for i, x in enumerate(items)}
        pending = set(futures)
        try:
            while pending:
                done, pending = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
                if not done:
                    stopping.check()  # a stop requested while the workers evaluate: they are ended below
                    continue
                for f in done:
                    yield futures[f], f.result()
        finally:
            for f in pending:
                f.cancel()

    def actors(self, factory: Callable[..., Any], args: Sequence[tuple]) -> ActorGroup:
        if self._workers == 1:
            return InlineActors(factory, args)
        return _ProcessActors(self._context(), factory, args)

    def runs_inline(self, n_items: int) -> bool:
        """One worker, or at most one item: ``imap`` calls the function here."""
        return self._workers == 1 or n_items <= 1

    def progress_queue(self) -> Optional[Any]:
        """A ``multiprocessing`` manager's queue, which pool workers reach (started on first use;
        its server process dies with the driver, as the workers do)."""
        if self._manager is None:
            from multiprocessing.managers import SyncManager

            manager = SyncManager(ctx=self._context())
            manager.start(_die_with_parent, _guard_args(self._method))
            self._manager, self._queue = manager, manager.Queue()
        return self._queue

    def close(self) -> None:
        if self._pool is not None:
            if stopping.requested() is not None:  # stopping: end the running evaluations, don't wait for them
                for proc in list(getattr(self._pool, "_processes", {}).values()):
                    proc.terminate()
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
        if self._manager is not None:
            self._manager.shutdown()
            self._manager = None
