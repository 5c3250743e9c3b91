"""Every built-in task has an ``experiment=smoke`` preset, and it runs end to end."""

import time

import pytest

from toolkit import plugins
from toolkit.config import compose, group_options
from toolkit.execution.runner import run

BUILTIN_TASKS = sorted(i.name for i in plugins.available("task") if i.dist == "jt")
#: extra overrides a task needs to be runnable at all (e.g. which prior to train)
NEEDS = {"pose_prior": ["action=pvae"]}


def test_there_are_builtin_tasks():
    assert BUILTIN_TASKS


@pytest.mark.parametrize("task", BUILTIN_TASKS)
def test_task_has_smoke_preset(task):
    assert f"smoke_{task}" in group_options("preset"), f"conf/preset/smoke_{task}.yaml is missing"
    assert task in group_options("task"), f"conf/task/{task}.yaml is missing"


@pytest.mark.parametrize("task", BUILTIN_TASKS)
def test_smoke_run_finishes(task, store_dir):
    t0 = time.perf_counter()
    res = run(compose([f"task={task}", *NEEDS.get(task, []), "experiment=smoke", f"store={store_dir}"]))
    elapsed = time.perf_counter() - t0
    run_info = res.store.get_run(res.run_id)
    assert run_info.info.status == "FINISHED"
    arts = list(res.store.artifact_dir(res.run_id).rglob("*.h5"))
    children = res.store.client.search_runs(
        [run_info.info.experiment_id], filter_string=f"tags.mlflow.parentRunId = '{res.run_id}'")
    for c in children:
        arts += list(res.store.artifact_dir(c.info.run_id).rglob("*.h5"))
    assert arts, "a run must leave at least one HDF5 artifact"
    print(f"{task}: smoke run took {elapsed:.1f}s")
