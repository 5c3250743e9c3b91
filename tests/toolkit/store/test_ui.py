"""jt ui: MLflow's UI with one worker and no job runners; SIGTERM stops it with the server, also
when jt was started as a shell's background job, and so does Ctrl-C; a busy or invalid port and an
environment that would make the server listen beyond loopback are one line and exit 2."""

import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request

import pytest

from tests.conftest import jt_env, run_jt
from tests.plugins.jt_executors.ray_cluster import free_port
from toolkit.errors import JtError
from toolkit.store.tracking import Store
from toolkit.store.ui import check_env, check_port, command


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
        page = urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=10).read().decode()
        assert page.index('<script data-jt="defaults">') < page.index("static-files/static/js/main")  # jt's app
        telemetry = urllib.request.urlopen(f"http://127.0.0.1:{port}/ajax-api/3.0/mlflow/ui-telemetry",
                                           timeout=10).read().decode()
        assert '"disable_ui_telemetry":true' in telemetry.replace(" ", "")
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
    from toolkit.store.ui import serve

    (tmp_path / "mlflow.db").write_bytes(b"not a database")
    with pytest.raises(JtError, match="not an SQLite database"):
        serve(tmp_path, free_port())


# ---------------------------------------------------------------------------- refused before MLflow starts
def test_a_busy_port_is_one_line_and_exit_2(tmp_path):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        out = run_jt("ui", f"store={tmp_path / 's'}", "--port", str(port), timeout=60)
    assert out.returncode == 2 and out.stderr.count("\n") == 1, out.stderr
    assert f"--port {port}: 127.0.0.1:{port} is already in use" in out.stderr
    assert "MLflow UI for" not in out.stdout and not (tmp_path / "s").exists()  # no URL, no store made


@pytest.mark.parametrize("port", ["0", "70000", "-1", "abc"])
def test_an_invalid_port_is_one_line_and_exit_2(tmp_path, port):
    out = run_jt("ui", f"store={tmp_path / 's'}", "--port", port, timeout=60)
    assert out.returncode == 2 and out.stderr.count("\n") == 1 and "--port" in out.stderr, out.stderr
    assert "MLflow UI for" not in out.stdout


def test_check_port_accepts_a_free_port():
    check_port(free_port())
    for bad in (0, 65536, True, "5000"):
        with pytest.raises(JtError, match="from 1 to 65535"):
            check_port(bad)


@pytest.mark.parametrize("env", [
    {"MLFLOW_GUNICORN_OPTS": "--timeout 60 -b 0.0.0.0:5000"},
    {"MLFLOW_GUNICORN_OPTS": "--bind=:5000"},
    {"MLFLOW_GUNICORN_OPTS": "-b[::]:5000"},
    {"MLFLOW_GUNICORN_OPTS": "--bind fd://3"},
    {"MLFLOW_GUNICORN_OPTS": "-b myhost.example.org:80"},
    {"GUNICORN_CMD_ARGS": "--bind=10.0.0.5:5000"},
    {"MLFLOW_UVICORN_OPTS": "--host 0.0.0.0"},
    {"MLFLOW_UVICORN_OPTS": "--host=::"},
    {"MLFLOW_UVICORN_OPTS": "--fd 3"},
    {"UVICORN_FD": "3"},
    {"MLFLOW_UVICORN_OPTS": "--host 'unbalanced"},
])
def test_environment_binding_beyond_loopback_is_refused(env):
    with pytest.raises(JtError, match="jt ui serves on 127.0.0.1 only") as e:
        check_env(env)
    assert "\n" not in str(e.value) and next(iter(env)) in str(e.value)


@pytest.mark.parametrize("env", [
    {},
    {"MLFLOW_GUNICORN_OPTS": "--timeout 60 -b 127.0.0.1:5000 --bind [::1]:5000 -b localhost:1 -b unix:/tmp/s"},
    {"MLFLOW_UVICORN_OPTS": "--timeout-keep-alive 30 --host 127.0.0.2 --uds /tmp/mlflow.sock"},
    {"MLFLOW_HOST": "0.0.0.0", "UVICORN_HOST": "0.0.0.0"},  # jt's --host 127.0.0.1 wins over both
    {"GUNICORN_CMD_ARGS": "", "UVICORN_FD": " "},
])
def test_environment_on_loopback_is_accepted(env):
    check_env(env)


def test_jt_ui_refuses_a_bind_beyond_loopback_in_one_line(tmp_path):
    env = {**jt_env(), "MLFLOW_GUNICORN_OPTS": "-b 0.0.0.0:5000"}
    out = subprocess.run([sys.executable, "-m", "toolkit.cli", "ui", f"store={tmp_path / 's'}", "--port",
                          str(free_port())], capture_output=True, text=True, env=env, timeout=60)
    assert out.returncode == 2 and out.stderr.count("\n") == 1, out.stderr
    assert "MLFLOW_GUNICORN_OPTS makes MLflow's server listen on 0.0.0.0:5000" in out.stderr


# ---------------------------------------------------------------------------- Ctrl-C stops the server tree
FAKE_UI = """
import os, subprocess, sys, time
from pathlib import Path
from toolkit.store import ui

def fake_command(root, port):  # a server process with a worker of its own, as MLflow + uvicorn
    tree = ("import os, subprocess, sys, time; c = subprocess.Popen([sys.executable, '-c', 'import time; "
            "time.sleep(600)']); open(sys.argv[1], 'w').write(f'{os.getpid()} {c.pid}'); time.sleep(600)")
    return [sys.executable, "-c", tree, str(root / "pids")], dict(os.environ)

ui.command = fake_command
from toolkit.cli import main
sys.argv = ["jt", "ui", f"store={sys.argv[1]}", "--port", sys.argv[2]]
main()
"""


def _fake_ui(tmp_path):
    """``jt ui`` on a store with MLflow replaced by a two-process tree; ``(jt's process, the
    tree's pids)`` once both are up. SIGINT is handled by default in jt, as in a terminal, also
    where the suite itself runs as a background job (which makes every process it starts ignore it)."""
    import sqlite3

    root = tmp_path / "s"
    root.mkdir()
    sqlite3.connect(root / "mlflow.db").execute("create table t (x)").connection.close()  # a store: no MLflow
    proc = subprocess.Popen([sys.executable, "-c", FAKE_UI, str(root), str(free_port())], env=jt_env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 60
    while not (root / "pids").is_file() or len((root / "pids").read_text().split()) < 2:
        if time.monotonic() > deadline or proc.poll() is not None:
            proc.kill()
            raise AssertionError(proc.communicate(timeout=10))
        time.sleep(0.1)
    return proc, [int(p) for p in (root / "pids").read_text().split()]


def _alive(pids):
    """The pids still running (zombies count as gone)."""
    return [p for p in pids if os.path.exists(f"/proc/{p}") and "Z" not in _state(p)]


def _wait_gone(pids, seconds):
    deadline = time.monotonic() + seconds
    while _alive(pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    return _alive(pids)


def test_ctrl_c_stops_the_server_and_its_worker(tmp_path):
    """SIGINT to ``jt ui`` (Ctrl-C in its terminal; the server has a session of its own, so only jt
    gets it) ends the server's whole process group. MLflow is replaced by a two-process tree."""
    proc, pids = _fake_ui(tmp_path)
    try:
        assert _alive(pids) == pids
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=30) == 0
        assert not _wait_gone(pids, 10), "outlived jt ui"
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_kill_9_of_jt_ui_stops_the_server_tree(tmp_path):
    """``kill -9`` of ``jt ui`` runs no handler of jt's: the guard in the server's group notices
    that jt is gone and ends the server and its worker (issue 15: the server used to keep the port)."""
    from toolkit.store import ui_guard

    proc, pids = _fake_ui(tmp_path)
    try:
        guard = [int(k[0]) for k in _children(proc.pid) if "ui_guard" in k[2]]
        assert len(guard) == 1, _children(proc.pid)
        proc.kill()
        proc.wait()
        assert not _wait_gone(pids + guard, 5 * ui_guard.PERIOD_S + 10), "the server outlived a kill -9 of jt ui"
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_the_guard_passes_the_servers_exit_status_on():
    """Run as jt runs it (a process of its own whose parent is the given pid), never in pytest's
    process: the guard signals its whole process group when it stops."""
    guard = [sys.executable, "-m", "toolkit.store.ui_guard"]
    done = subprocess.run([*guard, str(os.getpid()), sys.executable, "-c", "raise SystemExit(3)"], env=jt_env(),
                          start_new_session=True, capture_output=True, text=True, timeout=60)
    assert done.returncode == 3, done.stderr
    bad = subprocess.run([*guard, "nope", "x"], env=jt_env(), start_new_session=True, capture_output=True,
                         text=True, timeout=60)
    assert bad.returncode == 2 and "usage:" in bad.stderr


def _state(pid):
    try:
        return open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()[0]
    except OSError:
        return "Z"
