"""``executor=ray``: evaluations and rollout actors on a Ray cluster.

Install the extra (``pip install -e '.[ray]'``), start a cluster (``ray start --head`` on one
machine, ``ray start --address=HEAD:PORT`` on the others; see docs/cluster.md) and point
``executor.address`` at it. Ray has no local mode any more; on one machine use ``executor=local``.

Workers return results to the driver, which alone writes to the store. An evaluation's files are
written on the worker and shipped back with its result when the worker does not share the driver's
filesystem (``ship_files``; see ``jt_executors.ray_worker``), so a store served by an MLflow server
(``store=http://head:5000``) receives every file.

Failures never hang a run: an evaluation whose worker (or node, or one of its rollout actors) died
is retried up to ``max_retries`` times and then reported as a failed evaluation; one running longer
than ``eval_timeout_s`` is cancelled (its worker killed) and reported as failed. An exception raised
by the evaluation's own code reaches the caller, as with ``executor=local``.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time
from typing import Any, Callable, Iterator, Optional, Sequence

from jt_executors.ray_worker import SHIP_MODES, Outcome, jt_evaluate, pack, unpack, workdir_of
from toolkit.errors import JtError
from toolkit.interfaces import ActorGroup, Executor


class WorkerLost(RuntimeError):
    """Work (not an evaluation) whose worker died more often than ``max_retries`` allows."""


class _RayActors(ActorGroup):
    """Actors reserved together in one placement group, so groups never deadlock half-started."""

    def __init__(self, ray: Any, factory: Callable[..., Any], args: Sequence[tuple], cpus: float) -> None:
        from ray.util.placement_group import placement_group
        from ray.util.scheduling_strategies import PlacementGroupSchedulingStrategy

        self._ray = ray
        have = float(ray.cluster_resources().get("CPU", 0))
        if cpus * len(args) > have:  # the group could never start: say so instead of waiting forever
            raise JtError(f"{len(args)} actors of {cpus:g} CPUs (agent.n_workers, executor.cpus_per_task) "
                          f"do not fit the Ray cluster's {have:g} CPUs")
        self._pg = placement_group([{"CPU": cpus}] * len(args), strategy="PACK") if args else None

        @ray.remote(num_cpus=cpus, max_restarts=0)
        class _Holder:
            def __init__(self, *a: Any) -> None:
                self.obj = factory(*a)

            def call(self, method: str, margs: tuple) -> Any:
                return getattr(self.obj, method)(*margs)

        self._actors = [_Holder.options(scheduling_strategy=PlacementGroupSchedulingStrategy(self._pg, i))
                        .remote(*a) for i, a in enumerate(args)]
        self.size = len(self._actors)

    def call(self, method: str, args: Sequence[tuple] | None = None) -> list[Any]:
        args = args if args is not None else [()] * self.size
        return self._ray.get([h.call.remote(method, tuple(a)) for h, a in zip(self._actors, args)])

    def close(self) -> None:
        for h in self._actors:
            self._ray.kill(h)
        self._actors = []
        if self._pg is not None:
            from ray.util.placement_group import remove_placement_group

            remove_placement_group(self._pg)
            self._pg = None


def _log(msg: str) -> None:
    print(f"jt: {msg}", file=sys.stderr, flush=True)


def _lost_result(item: Any, reason: str, seconds: float) -> Any:
    """What an evaluation that could not finish returns: a failed ``Evaluation`` (NaN for its
    task's key metrics, so summaries that read them still work); other work raises ``WorkerLost``."""
    from toolkit import plugins
    from toolkit.execution.evaluate import Job
    from toolkit.interfaces import Evaluation

    if not isinstance(item, Job):
        raise WorkerLost(reason)
    try:
        keys = tuple(plugins.load("task", str(item.config["task"]["name"])).key_metrics)
    except Exception:  # noqa: BLE001 - the metrics are a courtesy; the failure is what matters
        keys = ()
    return Evaluation(metrics={k: math.nan for k in keys}, failed=True, reason=reason), seconds


def _check_reachable(address: str, timeout_s: float = 5.0) -> None:
    """A one-line ``JtError`` unless ``HOST:PORT`` accepts connections (``ray.init`` would retry
    a wrong address for minutes); ``auto`` and ``ray://`` addresses are left to Ray."""
    import socket

    host, sep, port = address.rpartition(":")
    if address == "auto" or "://" in address or not sep or not port.isdigit():
        return
    try:
        socket.create_connection((host, int(port)), timeout=timeout_s).close()
    except OSError as e:
        raise JtError(f"executor.address={address}: no Ray cluster answers there ({e.strerror or e}); "
                      "start one with: ray start --head --port=PORT") from None


@dataclasses.dataclass
class _Flight:
    """One item on the cluster: its index, attempt number and when the attempt started."""

    index: int
    attempt: int
    started: float


class RayExecutor(Executor):
    """Ray cluster: evaluations as tasks, rollout workers as actors."""

    @dataclasses.dataclass
    class Config:
        name: str = "ray"
        address: str = "auto"
        """Cluster address ``HOST:PORT`` (``ray start --head`` prints it); ``auto`` finds the
        cluster started on this machine (or ``$RAY_ADDRESS``)."""
        cpus_per_task: float = 1.0
        """CPUs reserved per evaluation or actor."""
        workers: int = 0
        """Evaluations (or actors) running at once; 0 means as many as the cluster has CPUs for.
        Same key as ``executor=local``, so presets such as ``experiment=smoke`` apply to both."""
        max_retries: int = 2
        """Times an evaluation is rerun after its worker, node or a rollout actor died; then it is
        reported as a failed evaluation (``jt.failure`` tag)."""
        eval_timeout_s: float = 0.0
        """Wall-clock limit of one evaluation (s); a longer one is cancelled and reported failed.
        0: no limit."""
        ship_files: str = "auto"
        """Send evaluation folders between driver and worker: ``auto`` (when the worker does not
        see the driver's folder), ``always`` (no shared filesystem) or ``never`` (shared)."""

    @classmethod
    def check_run(cls, cfg: Any) -> None:
        """Before a run opens: Ray is installed and a cluster answers at ``executor.address``
        (``HOST:PORT`` is tried; ``auto`` needs ``$RAY_ADDRESS`` or a cluster started on this
        machine), so a missing cluster is one line, not a FAILED run."""
        import importlib.util
        import os

        from toolkit.config import group_of

        if importlib.util.find_spec("ray") is None:
            raise JtError("executor=ray needs Ray: pip install -e '.[ray]'")
        address = str(group_of(group_of(cfg, "executor") or {}, "address") or "auto")
        if address == "auto" and not os.environ.get("RAY_ADDRESS") and \
                not os.path.exists(os.path.join(os.environ.get("RAY_TMPDIR", "/tmp"), "ray", "ray_current_cluster")):
            raise JtError("executor=ray: no Ray cluster on this machine (executor.address=auto); start one with "
                          "ray start --head, or give executor.address=HOST:PORT; on one machine executor=local "
                          "needs none")
        _check_reachable(address)

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        try:
            import ray
        except ImportError as e:  # a user mistake, reported as one line by the CLI
            raise JtError("executor=ray needs Ray: pip install -e '.[ray]'") from e
        self._ray = ray
        from toolkit.config import config_of

        params = config_of(self.Config, cfg, "executor=ray")  # a dict, a group node or a Config
        get = lambda k, d: getattr(params, k, d)  # noqa: E731
        self._ship = str(get("ship_files", "auto"))
        if self._ship not in SHIP_MODES:
            raise JtError(f"executor.ship_files={self._ship}: choose one of {', '.join(SHIP_MODES)}")
        self._cpus = float(get("cpus_per_task", 1.0))
        self._workers = int(get("workers", 0) or 0)
        self._retries = max(0, int(get("max_retries", 2)))
        self._timeout = float(get("eval_timeout_s", 0.0) or 0.0)
        self._owns = False
        if not ray.is_initialized():  # on a worker (PPO's actors inside an evaluation) it already is
            address = str(get("address", "auto"))
            _check_reachable(address)
            try:
                ray.init(address=address, ignore_reinit_error=True)
            except ConnectionError as e:
                raise JtError(f"executor.address={address}: no Ray cluster there ({e}); "
                              "start one with: ray start --head") from e
            self._owns = True

    @property
    def n_workers(self) -> int:
        if self._workers > 0:
            return self._workers
        return max(1, int(self._ray.cluster_resources().get("CPU", 1) // self._cpus))

    def imap(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> Iterator[tuple[int, Any]]:
        ray = self._ray
        remote = ray.remote(jt_evaluate).options(num_cpus=self._cpus, max_retries=0, retry_exceptions=False)
        width = self.n_workers
        todo = [(i, 0) for i in range(len(items))][::-1]  # (index, attempt); popped from the end
        flights: dict[Any, _Flight] = {}
        try:
            while todo or flights:
                while todo and len(flights) < width:
                    i, attempt = todo.pop()
                    files = pack(workdir_of(items[i])) if self._ship != "never" else None
                    flights[remote.remote(fn, items[i], files, self._ship)] = _Flight(i, attempt, time.monotonic())
                done, _ = ray.wait(list(flights), num_returns=1, timeout=self._wait_s(flights))
                for ref in done:
                    got = self._settle(flights.pop(ref), ref, items, todo)
                    if got is not None:
                        yield got
                for ref in self._overdue(flights):
                    f = flights.pop(ref)
                    ray.cancel(ref, force=True)
                    reason = f"timed out after {self._timeout:g} s (executor.eval_timeout_s)"
                    _log(f"evaluation {f.index} {reason}; reported as failed")
                    yield f.index, _lost_result(items[f.index], reason, time.monotonic() - f.started)
        finally:
            for ref in flights:
                ray.cancel(ref, force=True)

    def _wait_s(self, flights: dict[Any, _Flight]) -> Optional[float]:
        """How long to wait for a result: until the next deadline (None: no deadlines)."""
        if self._timeout <= 0 or not flights:
            return None
        first = min(f.started for f in flights.values()) + self._timeout
        return max(0.0, first - time.monotonic()) + 0.01

    def _overdue(self, flights: dict[Any, _Flight]) -> list[Any]:
        if self._timeout <= 0:
            return []
        now = time.monotonic()
        return [r for r, f in flights.items() if now - f.started >= self._timeout]

    def _settle(self, f: _Flight, ref: Any, items: Sequence[Any], todo: list) -> Optional[tuple[int, Any]]:
        """The finished attempt ``f``: its ``(index, result)``, or None when it was resubmitted."""
        from ray import exceptions as rex

        try:
            out: Outcome = self._ray.get(ref)
            reason = out.lost and f"{out.lost} (on {out.host})"
        except rex.RayTaskError:  # the evaluation's own exception (also an instance of its class)
            raise
        except rex.RayError as e:  # the worker process, its node or its object died
            out, reason = None, f"{type(e).__name__}: {str(e).splitlines()[0] if str(e) else 'worker lost'}"
        if not reason:
            wd = workdir_of(items[f.index])
            if out.files is not None and wd is not None:
                unpack(out.files, wd)
            return f.index, out.value
        if f.attempt < self._retries:
            _log(f"evaluation {f.index} was cut off ({reason}); retry {f.attempt + 1} of {self._retries}")
            todo.append((f.index, f.attempt + 1))
            return None
        _log(f"evaluation {f.index} was cut off ({reason}); reported as failed")
        return f.index, _lost_result(items[f.index], f"worker lost: {reason}", time.monotonic() - f.started)

    def actors(self, factory: Callable[..., Any], args: Sequence[tuple]) -> ActorGroup:
        return _RayActors(self._ray, factory, args, self._cpus)

    def close(self) -> None:
        if self._owns and self._ray.is_initialized():
            self._ray.shutdown()
        self._owns = False
