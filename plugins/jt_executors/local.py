"""``executor=local``: a process pool on this machine (the default)."""

from __future__ import annotations

import dataclasses
import multiprocessing as mp
import os
import traceback
from typing import Any, Callable, Iterator, Optional, Sequence

from toolkit.execution.actors import InlineActors
from toolkit.interfaces import ActorGroup, Executor


def _limit_threads() -> None:
    """One BLAS/torch thread per worker: the pool provides the parallelism."""
    for var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS", "NUMBA_NUM_THREADS"):
        os.environ[var] = "1"


def _actor_main(conn: Any, factory: Callable[..., Any], args: tuple) -> None:
    _limit_threads()
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



class _ProcessActors(ActorGroup):
    def __init__(self, ctx: Any, factory: Callable[..., Any], args: Sequence[tuple]) -> None:
        self._conns, self._procs = [], []
        for a in args:
            parent, child = ctx.Pipe()
            p = ctx.Process(target=_actor_main, args=(child, factory, a), daemon=True)
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
    """Process pool on this machine; one worker per core by default."""

    @dataclasses.dataclass
    class Config:
        name: str = "local"
        workers: int = 0
        """Worker processes; 0 means one per core. 1 runs everything in this process."""
        start_method: str = "spawn"
        """multiprocessing start method: spawn (safe with torch/pybullet), forkserver or fork."""

    def __init__(self, cfg: Any = None) -> None:
        from toolkit.config import config_of

        super().__init__(cfg)
        params = config_of(self.Config, cfg, "executor=local")  # a dict, a group node or a Config
        workers = int(params.workers or 0)
        self._workers = workers if workers > 0 else (os.cpu_count() or 1)
        self._method = str(params.start_method)
        self._pool: Optional[Any] = None

    @property
    def n_workers(self) -> int:
        return self._workers

    def _context(self) -> Any:
        return mp.get_context(self._method)

    def imap(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> Iterator[tuple[int, Any]]:
        if self._workers == 1 or len(items) <= 1:
            for i, x in enumerate(items):
                yield i, fn(x)
            return
        from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

        if self._pool is None:
            self._pool = ProcessPoolExecutor(
                max_workers=self._workers, mp_context=self._context(), initializer=_limit_threads
            )
        futures = {self._pool.submit(fn, x): i for i, x in enumerate(items)}
        pending = set(futures)
        try:
            while pending:
                done, pending = wait(pending, return_when=FIRST_COMPLETED)
                for f in done:
                    yield futures[f], f.result()
        finally:
            for f in pending:
                f.cancel()

    def actors(self, factory: Callable[..., Any], args: Sequence[tuple]) -> ActorGroup:
        if self._workers == 1:
            return InlineActors(factory, args)
        return _ProcessActors(self._context(), factory, args)

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
