"""executor=ray on a REAL two-node Ray cluster (``ray start --head`` + ``ray start --address``).

One cluster per module (two nodes of one CPU each, ~10 s to start), torn down by session id. It
runs the executor contract, a BDS search and a PPO training with rollout actors (same metrics as
``executor=local`` for the same seed), and kills workers mid-evaluation: a retried evaluation
gives the same result, one past ``max_retries`` is a failed evaluation, an overlong one times out.
Skipped when Ray is not installed (``pip install -e '.[test,ray]'``).
"""

from __future__ import annotations

import os
import re
import signal
import threading
import time

import pytest

from toolkit.testing.executor import Counter, ExecutorContract
from tests.plugins.jt_executors.ray_cluster import DRIVER_ENV, LocalRayCluster, node_of
from toolkit.config import compose
from toolkit.errors import JtError
from toolkit.execution.runner import run

ray = pytest.importorskip("ray")


@pytest.fixture(scope="module")
def cluster(example_plugin_dir):
    """Two nodes; their workers import the example plugin (``task=quadratic``)."""
    path = os.pathsep.join(p for p in (str(example_plugin_dir), os.environ.get("PYTHONPATH", "")) if p)
    with pytest.MonkeyPatch.context() as mp, LocalRayCluster(nodes=2, cpus=1, env={"PYTHONPATH": path}) as c:
        for k, v in DRIVER_ENV.items():
            mp.setenv(k, v)
        yield c


@pytest.fixture()
def driver(cluster):
    """The cluster's address; whatever happens, this process is disconnected afterwards."""
    yield cluster.address
    if ray.is_initialized():
        ray.shutdown()


class TestContractOnCluster(ExecutorContract):
    @pytest.fixture(scope="class")
    def executor(self, cluster):
        from jt_executors.ray import RayExecutor

        ex = RayExecutor(RayExecutor.Config(address=cluster.address, workers=2))
        yield ex
        ex.close()

    def test_actors_that_cannot_fit_are_refused(self, executor):
        with pytest.raises(JtError, match="3 actors of 1 CPUs .* do not fit the Ray cluster's 2 CPUs"):
            executor.actors(Counter, [(0,), (1,), (2,)])

    def test_work_spreads_over_both_nodes(self, executor):
        assert executor.n_workers == 2
        nodes = set()
        for _ in range(5):  # scheduling is Ray's; two parallel tasks need both one-CPU nodes
            nodes |= set(executor.map(node_of, [1.0, 1.0]))
            if len(nodes) == 2:
                break
        assert len(nodes) == 2


def _ray(address: str, *extra: str) -> list[str]:
    return ["executor=ray", f"executor.address={address}", *extra]


def test_bds_search_matches_local(driver, store_dir):
    common = ["task=strategy_landscape", "search=bds", "experiment=smoke", "seed=3", f"store={store_dir}"]
    local = run(compose(common))
    remote = run(compose([*common, *_ray(driver)]))
    assert len(remote.evaluations) == len(local.evaluations) == 10
    assert [e.point for e in remote.evaluations] == [e.point for e in local.evaluations]
    assert [e.metrics for e in remote.evaluations] == [e.metrics for e in local.evaluations]
    assert [list(e.features) for e in remote.evaluations] == [list(e.features) for e in local.evaluations]
    assert remote.metrics == local.metrics


class Watch:
    """Polls the cluster for processes titled ``title``; optionally SIGKILLs the first ``kill``."""

    def __init__(self, cluster: LocalRayCluster, title: str, kill: int = 0, after_s: float = 0.5) -> None:
        self.cluster, self.title, self.kill, self.after_s = cluster, title, kill, after_s
        self.seen: set[int] = set()
        self.killed: list[int] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._poll, daemon=True)

    def _poll(self) -> None:
        first: dict[int, float] = {}
        while not self._stop.is_set():
            for pid in self.cluster.workers(self.title):
                self.seen.add(pid)
                first.setdefault(pid, time.monotonic())
                if len(self.killed) < self.kill and pid not in self.killed \
                        and time.monotonic() - first[pid] >= self.after_s:
                    os.kill(pid, signal.SIGKILL)  # a worker of our own cluster, mid-evaluation
                    self.killed.append(pid)
            time.sleep(0.1)

    def __enter__(self) -> "Watch":
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join(timeout=5)


def test_ppo_with_rollout_actors_matches_local(driver, cluster, store_dir, capfd):
    """Rollout actors on the cluster; files shipped back as if no filesystem were shared."""
    import torch

    common = ["task=highjump", "experiment=smoke", "agent.n_workers=2", "seed=1", f"store={store_dir}"]
    threads = torch.get_num_threads()
    torch.set_num_threads(1)  # as on a one-CPU Ray worker (and a local pool worker): torch's sums
    try:  # depend on the thread count in the last bits
        local = run(compose(common))
    finally:
        torch.set_num_threads(threads)
    with Watch(cluster, "ray::_Holder") as actors:
        remote = run(compose([*common, *_ray(driver, "executor.ship_files=always")]))
    assert len(actors.seen) >= 2, "the rollout workers did not run as actors on the cluster"
    from toolkit import plugins

    # wall-time metrics differ between any two runs (the policy tasks do not list them as timing_metrics)
    timing = {"samples_per_s", "train_wall_s", *getattr(plugins.load("task", "highjump"), "timing_metrics", ())}
    same = lambda m: {k: v for k, v in m.items() if k not in timing and "wall" not in k}  # noqa: E731
    assert [same(e.metrics) for e in remote.evaluations] == [same(e.metrics) for e in local.evaluations]
    files = {p.name for p in remote.store.artifact_dir(remote.run_id).iterdir()}
    assert {"ppo.h5", "rollout.h5", "filmstrip.png", "config.yaml", "search.h5"} <= files

    # a rollout actor killed mid-training: the evaluation is rerun (from the checkpoint its shared
    # folder holds) and ends as the undisturbed one did
    with Watch(cluster, "ray::_Holder", kill=1, after_s=1.0) as w:
        again = run(compose([*common, *_ray(driver, "executor.max_retries=1")]))
    assert len(w.killed) == 1
    assert re.search(r"evaluation 0 was cut off \(ActorDiedError.*retry 1 of 1", capfd.readouterr().err)
    assert [same(e.metrics) for e in again.evaluations] == [same(e.metrics) for e in local.evaluations]


QUADRATIC = ["task=quadratic", "task.sleep=3.0", "search=random", "search.budget=2", "search.batch=1",
             "executor.workers=1", "seed=4"]


def _children(res):
    store = res.store
    exp = store.get_run(res.run_id).info.experiment_id
    kids = store.client.search_runs([exp], filter_string=f"tags.mlflow.parentRunId = '{res.run_id}'")
    return sorted(kids, key=lambda r: int(r.data.tags["jt.eval_index"]))


def test_killed_worker_is_retried(example_plugin, driver, cluster, store_dir, capfd):
    local = run(compose([*QUADRATIC, "task.sleep=0", f"store={store_dir}"]))
    with Watch(cluster, "ray::jt_evaluate", kill=1) as w:
        remote = run(compose([*QUADRATIC, f"store={store_dir}", *_ray(driver, "executor.max_retries=1")]))
    assert len(w.killed) == 1
    assert "retry 1 of 1" in capfd.readouterr().err
    assert not any(e.failed for e in remote.evaluations)
    assert [e.metrics for e in remote.evaluations] == [e.metrics for e in local.evaluations]
    assert all((r.info.status, r.data.metrics["failed"]) == ("FINISHED", 0.0) for r in _children(remote))


def test_worker_lost_past_retries_is_a_failed_evaluation(example_plugin, driver, cluster, store_dir):
    with Watch(cluster, "ray::jt_evaluate", kill=1) as w:
        res = run(compose([*QUADRATIC, f"store={store_dir}", *_ray(driver, "executor.max_retries=0")]))
    assert len(w.killed) == 1
    assert [e.failed for e in res.evaluations] == [True, False]
    assert res.evaluations[0].reason.startswith("worker lost")
    assert res.metrics["n_failed"] == 1.0
    first = _children(res)[0]
    assert first.data.tags["jt.failure"].startswith("worker lost") and first.data.metrics["failed"] == 1.0
    assert res.store.get_run(res.run_id).info.status == "FINISHED"


def test_overlong_evaluation_times_out(example_plugin, driver, store_dir):
    t0 = time.monotonic()
    res = run(compose([*QUADRATIC, "task.sleep=60", "search.budget=1", f"store={store_dir}",
                       *_ray(driver, "executor.eval_timeout_s=2")]))
    assert time.monotonic() - t0 < 45
    assert res.evaluations[0].failed and "timed out after 2 s" in res.evaluations[0].reason
    assert res.store.get_run(res.run_id).info.status == "FINISHED"
