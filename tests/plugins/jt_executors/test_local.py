"""executor=local: the process pool (and the in-process path for workers=1), through the shipped
contract suite (``toolkit.testing.executor``), as a third-party executor's tests use it."""

import os

import pytest

from jt_executors.local import LocalExecutor
from toolkit.testing.executor import Counter, ExecutorContract


class TestLocalPool(ExecutorContract):
    executor_cls, entry, cfg = LocalExecutor, "local", {"name": "local", "workers": 2}

    def test_actors_live_in_other_processes(self, executor):
        group = executor.actors(Counter, [(0,), (0,)])
        try:
            pids = group.call("pid")
        finally:
            group.close()
        assert len(set(pids)) == 2 and os.getpid() not in pids


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
