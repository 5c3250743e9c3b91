"""The contract every task passes, built-in or third-party: its config composes and is exactly
what ``jt run ... --cfg`` prints, its smoke preset runs end to end and leaves its artifacts, and
the same seed gives the same metrics.

A subclass sets ``task`` (the registry name) and, if needed, ``overrides`` (what the task needs to
run at all, e.g. ``action=pvae`` for the prior trainer) and ``plugin_path`` (where a third-party
task's distribution is installed, when it is not on the default path)::

    from toolkit.testing.task import TaskContract

    class TestMyTask(TaskContract):
        task = "mytask"        # needs conf task/mytask.yaml and preset/smoke_mytask.yaml
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import pytest


def _timing(key: str, task: str) -> bool:
    """Metrics that measure time (they differ between runs by nature): the task's own
    ``timing_metrics`` and the runner's and trainer's wall-time ones."""
    from toolkit import plugins

    return key in plugins.load("task", task).timing_metrics or key.endswith(("_s", "_seconds")) \
        or "per_s" in key or "wall" in key


@dataclasses.dataclass
class Finished:
    """A finished ``jt run``: its id and store."""

    run_id: str
    store: Any


def _finished_run(task: str, overrides: list, store: Any, pythonpath: str = "") -> Finished:
    """``jt run task=<task> experiment=smoke`` in a fresh process, as a user runs it (a run never
    depends on what else a process did before)."""
    import os
    import re
    import subprocess
    import sys

    from toolkit.store.tracking import store_root

    from toolkit.store.opening import open_store

    env = dict(os.environ)
    if pythonpath:
        env["PYTHONPATH"] = os.pathsep.join(p for p in (pythonpath, env.get("PYTHONPATH", "")) if p)
    out = subprocess.run([sys.executable, "-c", "from toolkit.cli import main; main()", "run", f"task={task}",
                          *overrides, "experiment=smoke", f"store={store}"], capture_output=True, text=True,
                         env=env, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    m = re.search(r"run ([0-9a-f]{32}) FINISHED", out.stdout)
    assert m, out.stdout[-2000:]
    return Finished(m.group(1), open_store(store_root(str(store))))


def _evaluation_runs(res: Any) -> list:
    info = res.store.get_run(res.run_id)
    kids = res.store.client.search_runs([info.info.experiment_id],
                                        filter_string=f"tags.mlflow.parentRunId = '{res.run_id}'")
    return [info] + list(kids)


class TaskContract:
    """Tests every task must pass (subclass as ``TestXxx`` with ``task`` set)."""

    task: str = ""
    overrides: tuple[str, ...] = ()
    def plugin_path(self, request: Any) -> str:
        """Where a third-party task's distribution is installed ("" for the built-ins)."""
        return ""

    @pytest.fixture(scope="class")
    def smoke(self, tmp_path_factory, request):
        store = tmp_path_factory.mktemp(f"store_{self.task}")
        return _finished_run(self.task, list(self.overrides), store, self.plugin_path(request))

    def test_has_its_yaml_and_smoke_preset(self):
        from toolkit.config import group_options

        assert self.task in group_options("task"), f"conf/task/{self.task}.yaml is missing"
        assert f"smoke_{self.task}" in group_options("preset"), f"preset/smoke_{self.task}.yaml is missing"

    def test_the_plugins_receive_what_cfg_prints(self):
        """Every typed group, rebuilt from the YAML that ``--cfg`` prints, gives each plugin the
        same ``Config`` as the composed config does (one source: nothing hidden, nothing lost)."""
        from omegaconf import OmegaConf

        from toolkit import plugins
        from toolkit.config import compose, config_of, to_yaml

        cfg = compose([f"task={self.task}", *self.overrides, "experiment=smoke"])
        printed = OmegaConf.create(to_yaml(cfg))
        task_cls = plugins.load("task", self.task)
        a = config_of(task_cls.Config, cfg.task, "task")
        b = config_of(task_cls.Config, printed.task, "task")
        assert a == b and dataclasses.is_dataclass(a)
        for group in plugins.KINDS:
            node = cfg.get(group)
            if node is None or "name" not in node:
                continue
            cls = plugins.load(group, str(node.name))
            if dataclasses.is_dataclass(getattr(cls, "Config", None)):
                assert config_of(cls.Config, node, group) == config_of(cls.Config, printed[group], group), group
        assert OmegaConf.to_container(cfg, resolve=True) == OmegaConf.to_container(printed, resolve=True)

    def test_its_declarations_are_well_formed(self):
        """``record_keys``, ``action_inputs`` and ``curriculum_attrs`` are None (not declared) or sets
        of names; the smoke preset's own choices satisfy them (composition checks them)."""
        from toolkit import plugins
        from toolkit.config import compose

        cls = plugins.load("task", self.task)
        for attr in ("record_keys", "action_inputs", "curriculum_attrs"):
            v = getattr(cls, attr, None)
            assert v is None or (isinstance(v, frozenset) and all(isinstance(k, str) for k in v)), attr
        compose([f"task={self.task}", *self.overrides, "experiment=smoke"])  # its own choices pass

    def test_smoke_run_finishes_with_its_artifacts(self, smoke):
        runs = _evaluation_runs(smoke)
        assert runs[0].info.status == "FINISHED"
        h5 = [p for r in runs for p in smoke.store.artifact_dir(r.info.run_id).rglob("*.h5")]
        assert h5, "a run must leave at least one HDF5 artifact"
        assert any(r.data.metrics for r in runs), "a run must log metrics"

    def test_same_seed_same_metrics(self, smoke, tmp_path, request):
        again = _finished_run(self.task, list(self.overrides), tmp_path, self.plugin_path(request))

        def finals(res: Any) -> dict:
            out = {}
            for r in _evaluation_runs(res):
                tag = r.data.tags.get("jt.eval_index", "outer")
                out.update({f"{tag}/{k}": v for k, v in r.data.metrics.items() if not _timing(k, self.task)})
            return out

        a, b = finals(smoke), finals(again)
        assert a.keys() == b.keys() and a
        for k in a:
            assert a[k] == b[k] or (math.isnan(a[k]) and math.isnan(b[k])), (k, a[k], b[k])
