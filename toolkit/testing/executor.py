"""The contract every jt executor meets; each executor's test module subclasses it.

A subclass sets ``executor_cls`` and ``entry`` (its registry name, also its
``executor/<entry>.yaml`` in a config root: jt's ``conf/`` or a ``jt.config`` package the plugin
ships) and may set ``cfg`` (what ``make()`` passes; ``{"name": entry}`` by default) or override the
class-scoped ``executor`` fixture (an executor that needs a cluster, say)::

    from toolkit.testing.executor import ExecutorContract

    class TestMyExecutor(ExecutorContract):
        executor_cls, entry = MyExecutor, "mine"

The work items are module-level functions and a class of this module (``square``, ``fails``,
``Counter``), so any executor that pickles work by reference (process pools, Ray) can run them.
"""

from __future__ import annotations

import dataclasses
import os
from importlib import metadata
from pathlib import Path
from typing import Any, ClassVar, Optional

import pytest

from toolkit.interfaces.executor import ActorGroup, Executor


def square(x: int) -> int:
    """A picklable unit of work."""
    return x * x


def fails(x: int) -> int:
    """Work that raises (the error must reach the caller)."""
    raise ValueError(f"bad item {x}")


class Counter:
    """A stateful actor: each worker keeps its own state between calls."""

    def __init__(self, start: int) -> None:
        self.value = start

    def add(self, k: int) -> int:
        """Add ``k``; the new value."""
        self.value += k
        return self.value

    def pid(self) -> int:
        """The process the actor lives in."""
        return os.getpid()

    def fail(self) -> None:
        """An actor method that raises."""
        raise ValueError(f"bad actor {self.value}")


class ExecutorContract:
    """Order, completeness, errors, per-actor state, ``n_workers``, ``close``; with ``executor_cls``
    set also the plugin's ``Config``, summary, YAML, the interface's ``workers`` key and the
    entry point."""

    executor_cls: ClassVar[Optional[type]] = None
    entry: ClassVar[str] = ""
    cfg: ClassVar[Any] = None

    def make(self) -> Executor:
        """A fresh executor from ``cfg`` (``{"name": entry}`` when unset)."""
        if self.executor_cls is None:
            pytest.skip("set executor_cls (or override the executor fixture)")
        return self.executor_cls(self.cfg if self.cfg is not None else {"name": self.entry})

    @pytest.fixture(scope="class")
    def executor(self):
        ex = self.make()
        yield ex
        ex.close()

    def _plugin(self) -> type:
        if self.executor_cls is None:
            pytest.skip("executor_cls not set: the plugin checks need the class")
        return self.executor_cls

    # ------------------------------------------------------------------ the work
    def test_map_keeps_input_order(self, executor):
        assert executor.map(square, list(range(7))) == [i * i for i in range(7)]

    def test_map_of_nothing_is_empty(self, executor):
        assert list(executor.map(square, [])) == []

    def test_imap_yields_every_index_once(self, executor):
        got = list(executor.imap(square, [3, 1, 2]))
        assert sorted(i for i, _ in got) == [0, 1, 2]
        assert dict(got) == {0: 9, 1: 1, 2: 4}

    def test_worker_errors_reach_the_caller(self, executor):
        with pytest.raises(Exception, match="bad item"):
            executor.map(fails, [1, 2])

    def test_still_works_after_an_error(self, executor):
        with pytest.raises(Exception, match="bad item"):
            executor.map(fails, [3])
        assert executor.map(square, [4, 5]) == [16, 25]

    def test_actors_keep_state_per_worker(self, executor):
        group = executor.actors(Counter, [(0,), (100,)])
        try:
            assert isinstance(group, ActorGroup) and len(group) == 2
            assert group.call("add", [(1,), (2,)]) == [1, 102]
            assert group.call("add", [(1,), (1,)]) == [2, 103]
        finally:
            group.close()

    def test_actor_errors_reach_the_caller(self, executor):
        group = executor.actors(Counter, [(7,)])
        try:
            with pytest.raises(Exception, match="bad actor 7"):
                group.call("fail")
        finally:
            group.close()

    def test_n_workers_positive(self, executor):
        assert isinstance(executor.n_workers, int) and executor.n_workers >= 1

    # ------------------------------------------------------------------ the plugin
    def test_is_an_executor_with_a_config(self):
        cls = self._plugin()
        assert issubclass(cls, Executor) and cls.summary()
        assert dataclasses.is_dataclass(cls.Config)
        fields = dataclasses.fields(cls.Config)
        assert fields and fields[0].name == "name" and fields[0].default == self.entry
        for f in fields:  # every YAML key has a default
            assert f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING

    def test_close_twice_and_as_context_manager(self):
        self._plugin()
        with self.make() as ex:
            assert ex.map(square, [2]) == [4]
        ex.close()  # closing again is harmless

    def test_yaml_selects_and_composition_types_it(self):
        """``executor=<entry>`` composes: the YAML names the plugin and the typed group builds it."""
        from omegaconf import OmegaConf

        from toolkit.config import _group_dirs, compose

        cls = self._plugin()
        path = next((Path(r) / "executor" / f"{self.entry}.yaml" for r in _group_dirs()
                     if (Path(r) / "executor" / f"{self.entry}.yaml").is_file()), None)
        assert path is not None, f"executor/{self.entry}.yaml is in no config root"
        assert OmegaConf.load(path).name == self.entry
        node = compose([f"executor={self.entry}", "task=zdt1"]).executor
        assert node.name == self.entry
        ex = cls(node)
        try:
            assert ex.map(square, [3]) == [9]
        finally:
            ex.close()

    def test_workers_key_of_the_interface_composes(self):
        """``executor.workers`` (``ExecutorKeys``, set by ``experiment=smoke`` and ``jt compare``)
        composes for every executor: kept when its ``Config`` declares it, left out otherwise."""
        from toolkit.config import compose

        cls = self._plugin()
        node = compose([f"executor={self.entry}", "executor.workers=1", "task=zdt1"]).executor
        declared = {f.name for f in dataclasses.fields(cls.Config)}
        assert (node.workers == 1) if "workers" in declared else ("workers" not in node)
        ex = cls(node)
        try:
            assert ex.map(square, [3]) == [9]
        finally:
            ex.close()

    def test_a_declared_common_key_is_the_interface_s(self):
        """A ``Config`` field named like one of ``ExecutorKeys`` has its type and its default
        (``workers: int = 0``, 0 meaning the executor's own choice)."""
        def type_name(t: Any) -> str:  # a class, or its name under ``from __future__ import annotations``
            return t.__name__ if isinstance(t, type) else str(t)

        cls = self._plugin()
        own = {f.name: f for f in dataclasses.fields(cls.Config)}
        for f in dataclasses.fields(Executor.common_keys):
            if f.name in own:
                assert type_name(own[f.name].type) == type_name(f.type), (f.name, own[f.name].type)
                assert own[f.name].default == f.default, (f.name, own[f.name].default)

    def test_unknown_key_is_one_clear_error(self):
        from toolkit.config import compose
        from toolkit.errors import JtError

        self._plugin()
        with pytest.raises(JtError, match="unknown key.*no_such_key"):
            compose([f"executor={self.entry}", "executor.no_such_key=1", "task=zdt1"])

    def test_registered_under_its_entry_point(self):
        cls = self._plugin()
        eps = {ep.name for ep in metadata.entry_points(group="jt.executors")}
        if self.entry not in eps:
            pytest.skip(f"jt.executors entry point '{self.entry}' not registered yet (pyproject)")
        from toolkit import plugins

        plugins.refresh()
        assert plugins.load("executor", self.entry) is cls
