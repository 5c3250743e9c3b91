"""jt ui: MLflow's UI with one worker and no job runners; SIGTERM stops it with the server, also
when jt was started as a shell's background job."""

import os
import signal
import subprocess
import sys
import time
import urllib.request

from tests.conftest import jt_env
from tests.plugins.jt_executors.ray_cluster import free_port
from toolkit.store.tracking import Store
from toolkit.store.ui import command


def _children(pid):
    out = subprocess.run(["ps", "-eo", "pid=,ppid=,args="], capture_output=True, text=True).stdout
    rows = [ln.split(None, 2) for ln in out.splitlines() if ln.strip()]
    kids, todo = [], [str(pid)]
    while todo:
        p = todo.pop()
        for r in rows:
            if r[1] == p:
                kids.append(r)
                todo.append(r[0])
    return kids


def test_command_is_one_worker_without_jobs(tmp_path):
    cmd, env = command(tmp_path, 5001)
    assert cmd[cmd.index("--workers") + 1] == "1" and env["MLFLOW_SERVER_ENABLE_JOB_EXECUTION"] == "false"
    assert cmd[cmd.index("--default-artifact-root") + 1] == str(tmp_path / "runs")


def test_ui_serves_the_store_and_stops_with_jt(tmp_path):
    store = Store(tmp_path / "s")
    store.end_run(store.start_run("exp", run_name="r"))
    port = free_port()
    # as a shell's background job: SIGINT ignored, inherited by everything jt starts
    proc = subprocess.Popen([sys.executable, "-m", "toolkit.cli", "ui", f"store={tmp_path / 's'}", "--port", str(port)],
                            env=jt_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))
    try:
        deadline, up = time.monotonic() + 120, False
        while time.monotonic() < deadline and not up and proc.poll() is None:
            try:
                up = urllib.request.urlopen(f"http://127.0.0.1:{port}/health", timeout=2).status == 200
            except OSError:
                time.sleep(0.3)
        assert up, proc.stderr.read() if proc.poll() is not None else "not up in 120 s"
        kids = _children(proc.pid)
        assert sum("uvicorn" in k[2] for k in kids) == 1, kids  # one server process, no extra workers
        assert not any("huey" in k[2] for k in kids), kids  # no job runners
        body = urllib.request.urlopen(f"http://127.0.0.1:{port}/ajax-api/2.0/mlflow/experiments/search?max_results=10",
                                      timeout=10).read().decode()
        assert '"exp"' in body
        t0 = time.monotonic()
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=30)
        assert time.monotonic() - t0 < 15  # stopped by SIGTERM, not by the SIGKILL that follows after 15 s
        time.sleep(1)
        assert not [k for k in kids if os.path.exists(f"/proc/{k[0]}")], "the server outlived jt ui"
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_a_bad_store_is_one_line_before_mlflow_starts(tmp_path):
    import pytest

    from toolkit.errors import JtError
    from toolkit.store.ui import serve

    (tmp_path / "mlflow.db").write_bytes(b"not a database")
    with pytest.raises(JtError, match="not an SQLite database"):
        serve(tmp_path, free_port())
