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
