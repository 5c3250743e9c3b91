"""``executor=ray``: evaluations and rollout actors on a Ray cluster.

Ray has no local mode any more; on one machine use ``executor=local``. Install the extra
(``pip install -e '.[ray]'``) and point ``executor.address`` at a running cluster
(``ray start --head`` prints it). Workers return results to the driver, which alone writes to the
MLflow store (SQLite is for one machine); evaluation files are written to ``EvalContext.workdir``,
so the store root must be on a filesystem the workers share.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Callable, Iterator, Sequence

from toolkit.interfaces import ActorGroup, Executor


class _RayActors(ActorGroup):
    def __init__(self, ray: Any, factory: Callable[..., Any], args: Sequence[tuple], cpus: float) -> None:
        self._ray = ray

        @ray.remote(num_cpus=cpus)
        class _Holder:
            def __init__(self, *a: Any) -> None:
                self.obj = factory(*a)

            def call(self, method: str, margs: tuple) -> Any:
                return getattr(self.obj, method)(*margs)

        self._actors = [_Holder.remote(*a) for a in args]
        self.size = len(self._actors)

    def call(self, method: str, args: Sequence[tuple] | None = None) -> list[Any]:
        args = args if args is not None else [()] * self.size
        return self._ray.get([h.call.remote(method, tuple(a)) for h, a in zip(self._actors, args)])

    def close(self) -> None:
        for h in self._actors:
            self._ray.kill(h)
        self._actors = []


class RayExecutor(Executor):
    """Ray cluster: evaluations as tasks, rollout workers as actors."""

    @dataclasses.dataclass
    class Config:
        name: str = "ray"
        address: str = "auto"
        """Cluster address (``ray start --head`` prints it); ``auto`` finds a running one."""
        cpus_per_task: float = 1.0
        """CPUs reserved per evaluation or actor."""
        workers: int = 0
        """Evaluations (or actors) running at once; 0 means as many as the cluster has CPUs for.
        Same key as ``executor=local``, so presets such as ``experiment=smoke`` apply to both."""

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        try:
            import ray
        except ImportError as e:  # a user mistake, reported as one line by the CLI
            raise RuntimeError("executor=ray needs Ray: pip install -e '.[ray]'") from e
        self._ray = ray
        if not ray.is_initialized():
            ray.init(address=getattr(cfg, "address", "auto"), ignore_reinit_error=True)
        self._cpus = float(getattr(cfg, "cpus_per_task", 1.0))
        self._workers = int(getattr(cfg, "workers", 0) or 0)

    @property
    def n_workers(self) -> int:
        if self._workers > 0:
            return self._workers
        return max(1, int(self._ray.cluster_resources().get("CPU", 1) // self._cpus))

    def imap(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> Iterator[tuple[int, Any]]:
        remote = self._ray.remote(num_cpus=self._cpus)(fn)
        todo = list(enumerate(items))[::-1]
        refs: dict[Any, int] = {}
        while todo or refs:
            while todo and len(refs) < self.n_workers:  # keep at most n_workers in flight
                i, x = todo.pop()
                refs[remote.remote(x)] = i
            done, _ = self._ray.wait(list(refs), num_returns=1)
            for r in done:
                yield refs.pop(r), self._ray.get(r)

    def actors(self, factory: Callable[..., Any], args: Sequence[tuple]) -> ActorGroup:
        return _RayActors(self._ray, factory, args, self._cpus)
