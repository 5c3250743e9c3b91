"""executor=local: the process pool (and the in-process path for workers=1)."""

import os

import pytest

from jt_executors.local import LocalExecutor
from tests.plugins.jt_executors.executor_contract import Counter, ExecutorContract


class TestLocalPool(ExecutorContract):
    @pytest.fixture(scope="class")
    def executor(self):
        ex = LocalExecutor(LocalExecutor.Config(workers=2))
        yield ex
        ex.close()

    def test_actors_live_in_other_processes(self, executor):
        group = executor.actors(Counter, [(0,), (0,)])
        try:
            pids = group.call("pid")
        finally:
            group.close()
        assert len(set(pids)) == 2 and os.getpid() not in pids


class TestLocalInline(ExecutorContract):
    @pytest.fixture(scope="class")
    def executor(self):
        return LocalExecutor(LocalExecutor.Config(workers=1))
