"""What every executor plugin must do; each executor's test subclasses ``ExecutorContract``."""

from __future__ import annotations

import os

import pytest


def square(x: int) -> int:
    """A picklable unit of work."""
    return x * x


def fails(x: int) -> int:
    raise ValueError(f"bad item {x}")


class Counter:
    """A stateful actor: each worker keeps its own state between calls."""

    def __init__(self, start: int) -> None:
        self.value = start

    def add(self, k: int) -> int:
        self.value += k
        return self.value

    def pid(self) -> int:
        return os.getpid()


class ExecutorContract:
    """Subclass and provide the ``executor`` fixture."""

    def test_map_keeps_input_order(self, executor):
        assert executor.map(square, list(range(7))) == [i * i for i in range(7)]

    def test_imap_yields_every_index_once(self, executor):
        got = dict(executor.imap(square, [3, 1, 2]))
        assert got == {0: 9, 1: 1, 2: 4}

    def test_worker_errors_reach_the_caller(self, executor):
        with pytest.raises(Exception, match="bad item"):
            executor.map(fails, [1, 2])

    def test_actors_keep_state_per_worker(self, executor):
        group = executor.actors(Counter, [(0,), (100,)])
        try:
            assert group.call("add", [(1,), (2,)]) == [1, 102]
            assert group.call("add", [(1,), (1,)]) == [2, 103]
        finally:
            group.close()

    def test_n_workers_positive(self, executor):
        assert executor.n_workers >= 1
