"""Every built-in task and the third-party example task pass the task contract suite."""

from __future__ import annotations

import pytest

from toolkit import plugins
from toolkit.testing.task import TaskContract

BUILTIN_TASKS = sorted(i.name for i in plugins.available("task") if i.dist == "jt")
NEEDS = {"pose_prior": ("action=pvae",)}  #: what a task needs to run at all (which prior to train)


def test_every_builtin_task_has_a_contract_class():
    tested = {c.task for c in globals().values() if isinstance(c, type) and issubclass(c, TaskContract)}
    assert set(BUILTIN_TASKS) <= tested, set(BUILTIN_TASKS) - tested


for _name in BUILTIN_TASKS:
    globals()[f"Test_{_name}"] = type(f"Test_{_name}", (TaskContract,), {"task": _name, "overrides": NEEDS.get(_name, ())})


@pytest.mark.usefixtures("example_plugin")
class TestThirdPartyQuadratic(TaskContract):
    task = "quadratic"

    def plugin_path(self, request):
        return str(request.getfixturevalue("example_plugin_dir"))
