"""The MLflow store: SQLite tracking, buffered metrics, concurrent processes."""

import subprocess
import sys

from toolkit.store.tracking import Store


def test_runs_metrics_and_artifacts(tmp_path):
    store = Store(tmp_path / "s")
    assert (tmp_path / "s" / "mlflow.db").is_file()
    rid = store.start_run("exp", run_name="r", tags={"jt.k": "v"})
    with store.metrics(rid) as buf:
        for i in range(2500):  # more than one log_batch
            buf.add("loss", 1.0 / (i + 1), step=i)
    history = store.client.get_metric_history(rid, "loss")
    assert len(history) == 2500 and history[-1].step == 2499
    f = tmp_path / "x.txt"
    f.write_text("hi")
    store.log_artifact(rid, f)
    assert (store.artifact_dir(rid) / "x.txt").read_text() == "hi"
    assert str(store.artifact_dir(rid)).startswith(str(tmp_path / "s" / "runs" / "exp"))
    store.end_run(rid, "KILLED", "because")
    run = store.get_run(rid)
    assert run.info.status == "KILLED" and run.data.tags["jt.reason"] == "because"


SCRIPT = """
import sys
from toolkit.store.tracking import Store
s = Store(sys.argv[1])
for i in range(5):
    r = s.start_run("shared")
    with s.metrics(r) as b:
        b.add_many({"m": i, "n": 2 * i})
    s.end_run(r)
print("ok")
"""


def test_two_processes_share_a_new_store(tmp_path):
    root = tmp_path / "fresh"
    procs = [subprocess.Popen([sys.executable, "-c", SCRIPT, str(root)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for _ in range(2)]
    outs = [p.communicate(timeout=240) for p in procs]
    assert all(p.returncode == 0 for p in procs), [o[1][-2000:] for o in outs]
    store = Store(root)
    runs = store.client.search_runs([store.experiment_id("shared")])
    assert len(runs) == 10 and all(r.info.status == "FINISHED" for r in runs)


def test_a_metric_is_logged_once_per_step_with_its_own_time(tmp_path):
    store = Store(tmp_path / "s")
    rid = store.start_run("exp")
    with store.metrics(rid) as buf:
        assert buf.add("loss", 1.0, step=3, timestamp=1_700_000_000.25)
        assert not buf.add("loss", 9.0, step=3)  # a second value at step 3 is dropped
        buf.add("loss", 0.5, step=4, timestamp=1_700_000_001.5)
    hist = sorted(store.client.get_metric_history(rid, "loss"), key=lambda m: m.step)
    assert [(m.step, m.value, m.timestamp) for m in hist] == [(3, 1.0, 1_700_000_000_250), (4, 0.5, 1_700_000_001_500)]


def test_nothing_lives_outside_the_store(tmp_path, monkeypatch):
    """MLflow makes its "Default" experiment at <cwd>/mlruns/0; jt moves it into the store."""
    monkeypatch.chdir(tmp_path)
    store = Store(tmp_path / "s")
    assert store.client.get_experiment("0").artifact_location == str(tmp_path / "s" / "runs" / "Default")
    eid = store.describe_experiment("exp", "what these runs are", {"jt.task": "exp"})
    store.describe_experiment("exp", "another text", {"jt.task": "other"})  # a description is not replaced
    tags = store.client.get_experiment(eid).tags
    assert tags["mlflow.note.content"] == "what these runs are" and tags["jt.task"] == "exp"
    assert not (tmp_path / "mlruns").exists()


def test_an_h5_artifact_gets_a_preview_beside_it(tmp_path):
    import numpy as np

    from toolkit.store import h5

    store = Store(tmp_path / "s")
    rid = store.start_run("exp")
    folder = tmp_path / "files"
    h5.write(folder / "sub" / "data.h5", {"q": np.zeros((4, 3))}, attrs={"format": "x/1"})
    (folder / "sub" / "data.h5.txt").write_text("stale preview of an earlier write")
    store.log_artifacts(rid, folder)
    art = store.artifact_dir(rid)
    text = (art / "sub" / "data.h5.txt").read_text()
    assert "q  4×3 float64" in text and "@format = x/1" in text
    assert sorted(p.name for p in (art / "sub").iterdir()) == ["data.h5", "data.h5.txt"]
