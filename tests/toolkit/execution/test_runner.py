"""The runner end to end on the third-party example task: nested runs, artifacts, resume."""

import os
import signal
import sqlite3
import subprocess
import sys
import time

import numpy as np
import pytest

from tests.conftest import jt_env
from toolkit.config import compose
from toolkit.execution.runner import run
from toolkit.store import h5


def test_search_runs_evaluations_as_nested_runs(example_plugin, store_dir):
    cfg = compose(["task=quadratic", "search=random", "search.budget=4", "search.batch=2",
                   "executor.workers=1", f"store={store_dir}", "seed=3"])
    res = run(cfg)
    store = res.store
    outer = store.get_run(res.run_id)
    assert outer.info.status == "FINISHED"
    assert outer.data.tags["jt.seed"] == "3" and "jt.git_commit" in outer.data.tags
    assert outer.data.params["task.name"] == "quadratic"
    children = store.client.search_runs([outer.info.experiment_id],
                                        filter_string=f"tags.mlflow.parentRunId = '{res.run_id}'")
    assert len(children) == 4 and all(c.info.status == "FINISHED" for c in children)
    for c in children:
        art = store.artifact_dir(c.info.run_id)
        data = h5.read(art / "evaluation.h5")
        assert np.isclose(data["value"], c.data.metrics["value"])
        assert {"feature_0", "objective_value", "eval_seconds"} <= set(c.data.metrics)
        assert len(store.client.get_metric_history(c.info.run_id, "train/curve")) == 5
    hist = h5.read(store.artifact_dir(res.run_id) / "search_history.h5")
    assert hist["x"].shape == (4, 2) and list(hist["batch"]) == [0, 0, 1, 1]
    assert outer.data.metrics["n_evaluations"] == 4
    values = [c.data.metrics["value"] for c in sorted(children, key=lambda c: int(c.data.tags["jt.eval_index"]))]
    best = store.client.get_metric_history(res.run_id, "best_so_far")  # a summarize() curve
    assert [m.step for m in sorted(best, key=lambda m: m.step)] == [1, 2, 3, 4]
    assert [m.value for m in sorted(best, key=lambda m: m.step)] == pytest.approx(np.minimum.accumulate(values))


def test_same_seed_same_result(example_plugin, store_dir):
    a = run(compose(["task=quadratic", "search=random", "search.budget=3", "executor.workers=1",
                     f"store={store_dir}", "seed=5"]))
    b = run(compose(["task=quadratic", "search=random", "search.budget=3", "executor.workers=1",
                     f"store={store_dir}", "seed=5"]))
    c = run(compose(["task=quadratic", "search=random", "search.budget=3", "executor.workers=1",
                     f"store={store_dir}", "seed=6"]))
    va = [e.metrics["noise0"] for e in a.evaluations]
    assert va == [e.metrics["noise0"] for e in b.evaluations]
    assert va != [e.metrics["noise0"] for e in c.evaluations]


def test_parallel_executor_gives_the_same_results(example_plugin, store_dir):
    common = ["task=quadratic", "search=random", "search.budget=4", "search.batch=4",
              f"store={store_dir}", "seed=2"]
    serial = run(compose([*common, "executor.workers=1"]))
    pooled = run(compose([*common, "executor.workers=2"]))
    assert [e.metrics for e in serial.evaluations] == [e.metrics for e in pooled.evaluations]


def _runs(db):
    con = sqlite3.connect(db)
    try:
        return con.execute("select run_uuid, status from runs").fetchall()
    except sqlite3.OperationalError:
        return []
    finally:
        con.close()


def test_killed_run_resumes_from_last_completed_evaluation(example_plugin, example_plugin_dir, store_dir):
    args = [sys.executable, "-m", "toolkit.cli", "run", "task=quadratic", "task.sleep=1.0",
            "search=random", "search.budget=6", "executor.workers=1", f"store={store_dir}", "seed=1"]
    proc = subprocess.Popen(args, env=jt_env(example_plugin_dir), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    db = store_dir / "mlflow.db"
    deadline = time.time() + 120
    outer = None
    while time.time() < deadline:  # wait until two evaluations have finished
        done = [r for r in _runs(db) if r[1] == "FINISHED"] if db.exists() else []
        if len(done) >= 2:
            outer = [r for r in _runs(db) if r[1] == "RUNNING"]
            break
        time.sleep(0.2)
    os.kill(proc.pid, signal.SIGKILL)  # no chance to clean up
    proc.communicate()
    assert outer, "run did not get going"
    p = subprocess.run([sys.executable, "-m", "toolkit.cli", "run", f"resume={_outer_id(store_dir)}",
                        f"store={store_dir}"], env=jt_env(example_plugin_dir), capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert "resumed after" in p.stderr
    from toolkit.store.tracking import Store

    store = Store(store_dir)
    rid = _outer_id(store_dir)
    hist = h5.read(store.artifact_dir(rid) / "search_history.h5")
    assert list(hist["index"]) == list(range(6))
    # the same points an uninterrupted run would have evaluated
    ref = run(compose(["task=quadratic", "search=random", "search.budget=6", "executor.workers=1",
                       f"store={store_dir}", "seed=1"]))
    np.testing.assert_allclose(hist["x"], np.stack([[e.point["x0"], e.point["x1"]] for e in ref.evaluations]))
    children = store.client.search_runs([store.get_run(rid).info.experiment_id],
                                        filter_string=f"tags.mlflow.parentRunId = '{rid}'")
    statuses = sorted(c.info.status for c in children)
    assert statuses.count("FINISHED") == 6 and set(statuses) <= {"FINISHED", "KILLED"}
    names = [c.info.run_name for c in children]
    assert sorted(c.info.run_name for c in children if c.info.status == "FINISHED") == \
        [f"eval-{i:04d}" for i in range(6)]
    assert len(set(names)) == len(names)  # a cut-off evaluation is eval-NNNN·interrupted, KILLED
    assert all(n.endswith("·interrupted") for c, n in zip(children, names) if c.info.status == "KILLED")
    assert store.get_run(rid).info.status == "FINISHED"


def _outer_id(store_dir):
    from toolkit.store.tracking import Store

    store = Store(store_dir)
    exp = store.experiment_id("quadratic")
    runs = store.client.search_runs([exp], filter_string="tags.`jt.search` = 'random'")
    return sorted(runs, key=lambda r: r.info.start_time)[0].info.run_id


def test_interrupt_marks_run_killed_with_reason(example_plugin_dir, store_dir):
    args = [sys.executable, "-m", "toolkit.cli", "run", "task=quadratic", "task.sleep=20",
            "executor.workers=1", f"store={store_dir}"]
    proc = subprocess.Popen(args, env=jt_env(example_plugin_dir), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    db = store_dir / "mlflow.db"
    deadline = time.time() + 120
    while time.time() < deadline and not (db.exists() and _runs(db)):
        time.sleep(0.2)
    time.sleep(1.0)
    # SIGTERM, not SIGINT: a shell that starts jobs in the background makes them ignore SIGINT
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "resume=" in err
    (rid, status), = _runs(db)
    assert status == "KILLED"
    con = sqlite3.connect(db)
    reason = con.execute("select value from tags where key='jt.reason'").fetchone()[0]
    assert "sigterm" in reason.lower()


def test_long_evaluations_show_progress_even_in_parallel_workers(example_plugin_dir, store_dir):
    """Progress lines come from evaluations that run longer than QUIET_S, whichever worker runs
    them (a PPO training in a pool worker is silent for minutes otherwise; workers report through
    the executor's queue to the driver, which writes at most one line per LINE_EVERY_S off a
    terminal, with the run's share and ETA); short ones stay quiet."""
    from tests.conftest import run_jt

    common = ["run", "task=quadratic", "search=random", "search.budget=2", "search.batch=2", "executor.workers=2",
              f"store={store_dir}"]
    slow = run_jt(*common, "task.sleep=3.0", extra_path=example_plugin_dir)
    assert slow.returncode == 0, slow.stderr
    lines = [ln for ln in slow.stderr.splitlines() if "% bowl" in ln]
    assert lines and all("task=quadratic:" in ln and "ETA" in ln for ln in lines), slow.stderr
    assert "jt: [2/2]" in slow.stderr
    fast = run_jt(*common, "task.sleep=0", extra_path=example_plugin_dir)
    assert fast.returncode == 0 and "% bowl" not in fast.stderr


def test_runs_read_well_in_the_ui(example_plugin, store_dir):
    """What a researcher meets in ``jt ui``: finals and curves under distinct keys, each logged once,
    curve points with their own times, descriptions, MLflow's user/commit tags, an experiment
    description, the outer run's summary picture and table, HDF5 previews, no store outside the store."""
    args = ["task=quadratic", "task.sleep=0.05", "search=random", "search.budget=2", "search.batch=2",
            "executor.workers=1", f"store={store_dir}", "seed=4"]
    command = " ".join(["jt", "run", *args])  # as the CLI passes it (this process's argv is pytest's)
    res = run(compose(args), command=command)
    store = res.store
    outer = store.get_run(res.run_id)
    child = store.client.search_runs([outer.info.experiment_id],
                                     filter_string=f"tags.mlflow.parentRunId = '{res.run_id}'",
                                     order_by=["attributes.run_name"])[0]
    cid = child.info.run_id
    assert child.info.run_name == "eval-0000"
    final = store.client.get_metric_history(cid, "value")
    assert [m.step for m in final] == [0]  # the final value once, at step 0
    curve = sorted(store.client.get_metric_history(cid, "train/curve"), key=lambda m: m.step)
    assert [m.step for m in curve] == [0, 1, 2, 3, 4]
    assert store.client.get_metric_history(cid, "curve") == []  # no bare key mixing curve and final
    times = [m.timestamp for m in curve]
    assert times == sorted(times) and len(set(times)) == 5  # each point its own time (~10 ms apart)
    assert times[-1] - times[0] >= 30
    for key in child.data.metrics:  # nothing logged twice at one step
        steps = [m.step for m in store.client.get_metric_history(cid, key)]
        assert len(steps) == len(set(steps)), key
    note = child.data.tags["mlflow.note.content"]
    assert note.startswith("**Evaluation 0** of `quadratic·random·seed4` at `x0=")
    assert "| value |" in note and "`evaluation.h5`" not in note  # pictures only, none here
    tags = outer.data.tags
    assert tags["mlflow.user"] and tags["mlflow.source.git.commit"] == tags["jt.git_commit"].split("+")[0]
    desc = tags["mlflow.note.content"]
    assert f"Reproduce: `{command}`" in desc and "| n_evaluations | 2 |" in desc and "`points.png`" in desc
    assert "| eval | x0 | x1 | value |" in desc  # the task's summary_table, as markdown
    art = store.artifact_dir(res.run_id)
    assert (art / "points.png").stat().st_size > 1000  # the task's summary_artifacts, on the outer run
    import json

    table = json.loads((art / "summary_table.json").read_text())
    assert table["header"] == ["eval", "x0", "x1", "value"] and len(table["rows"]) == 2
    preview = (art / "search_history.h5.txt").read_text()  # a preview beside every .h5
    assert "@format = jt.search_history/1" in preview and "\nx  2×2 float64" in preview
    assert "\nhistory/\n" in (art / "search.h5.txt").read_text()
    assert "x  2 float64" in (store.artifact_dir(cid) / "evaluation.h5.txt").read_text()
    exp = store.client.get_experiment(outer.info.experiment_id)
    assert "quadratic" in exp.tags["mlflow.note.content"] and exp.tags["jt.task"] == "quadratic"
    assert exp.tags["mlflow.experimentKind"] == "custom_model_development"  # the UI opens "Model training"
    default = store.client.get_experiment("0")
    assert default.artifact_location.startswith(str(store.root))


def test_a_bad_summary_hook_is_a_warning_not_a_lost_run(tmp_path):
    """A summary_artifacts path that is no file is skipped (and said); a ragged table is dropped."""
    from toolkit.execution import runner
    from toolkit.interfaces import Evaluation
    from toolkit.store.tracking import Store

    class Sloppy:
        def summary_artifacts(self, evaluations, folder):
            (folder / "ok.png").write_bytes(b"png")
            return [folder / "ok.png", folder / "missing.png"]

        def summary_table(self, evaluations):
            return ["a", "b"], [[1, 2], [3]]

    store = Store(tmp_path / "s")
    rid = store.start_run("e")
    evs = [Evaluation(metrics={"v": 1.0})]
    assert runner._summary_artifacts(store, rid, Sloppy(), evs, tmp_path / "pics") == ["ok.png"]
    assert (store.artifact_dir(rid) / "ok.png").is_file()
    assert runner._summary_table(Sloppy(), evs, tmp_path) is None
    assert not (tmp_path / "summary_table.json").exists()


def test_single_logs_each_metric_once_on_the_outer_run(example_plugin, store_dir):
    """search=single evaluates in the outer run: the task's summary of the same name (spd_tracking
    averages its one evaluation) is not logged a second time at step 0."""
    res = run(compose(["task=quadratic", "executor.workers=1", f"store={store_dir}"]))
    store = res.store
    assert [m.step for m in store.client.get_metric_history(res.run_id, "value")] == [0]
    assert len(store.client.get_metric_history(res.run_id, "train/curve")) == 5
    note = store.get_run(res.run_id).data.tags["mlflow.note.content"]
    assert "one evaluation of task `quadratic`, in this run" in note and "`points.png`" in note
