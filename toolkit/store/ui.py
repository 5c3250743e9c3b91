"""``jt ui``: MLflow's UI on a folder store, started lean (one worker, no job runners).

MLflow's server by default starts 4 uvicorn workers and a set of job runners (for its GenAI
features, which jt does not use): ~30 s to come up on two cores. One worker and no jobs serve
a researcher's browser as well and are up in a few seconds.

It listens on 127.0.0.1 only (the store's runs, params and files are not for the network; a
tracking server is ``mlflow server``, docs/cluster.md). A ``--port`` out of range or already in
use, or an environment variable MLflow or its web server would read to listen elsewhere, is one
``JtError`` line before MLflow starts (``check``).

MLflow 3 opens in its GenAI view (traces, evaluations, an assistant panel); jt's runs live in its
"Model training" view. ``jt ui`` opens there (MLflow 3.17):

- the URLs it prints carry ``workflowType=machine_learning`` (what the UI's GenAI / Model training
  switch puts in the URL) and open each task's runs page in a saved view, ``jt: key metrics``, whose
  columns are the task's ``key_metrics`` (MLflow keeps a saved view in the experiment tag
  ``mlflow.sharedViewState.<key>`` and opens it from ``?viewStateShareKey=<key>``);
- jt's experiments carry ``mlflow.experimentKind = custom_model_development`` (the tag MLflow's
  "experiment type" selector writes), set when jt creates them (``experiment_tags``) and on
  existing stores when ``jt ui`` opens them (``prepare``);
- the server is MLflow's own app behind ``toolkit.store.ui_app`` (the ``mlflow.app`` entry point
  ``jt-ui``), whose page makes "Model training" the browser's default view (clicking into a run
  stays there) and keeps the assistant panel closed until its button is pressed;
- the server sends no usage data (``MLFLOW_DISABLE_TELEMETRY``, ``DO_NOT_TRACK``).
"""

from __future__ import annotations

import errno
import ipaddress
import json
import os
import shlex
import signal
import socket
import sqlite3
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Mapping, Optional, Sequence

from toolkit.errors import JtError

#: environment variables holding server options MLflow forwards (``mlflow server --gunicorn-opts``
#: / ``--uvicorn-opts``) or that gunicorn reads itself; a bind in one is checked by ``check_env``
OPTION_VARIABLES = ("MLFLOW_GUNICORN_OPTS", "MLFLOW_UVICORN_OPTS", "GUNICORN_CMD_ARGS")


KIND_TAG, KIND = "mlflow.experimentKind", "custom_model_development"
"""The experiment tag MLflow files an experiment's type under, and its "Machine learning" value."""
MODEL_TRAINING = "workflowType=machine_learning"
"""The URL parameter of MLflow's "Model training" view (its GenAI / Model training switch)."""
VIEW_KEY = "jt"
VIEW_TAG = f"mlflow.sharedViewState.{VIEW_KEY}"
"""The experiment tag of jt's saved view; ``?viewStateShareKey=jt`` opens it."""
VIEW_NAME = "jt: key metrics"
APP_NAME = "jt-ui"
"""jt's ``mlflow.app`` entry point (``toolkit.store.ui_app:app``), given to ``mlflow ui --app-name``."""


def url(port: int, experiment_id: Optional[str] = None, view: bool = False) -> str:
    """Where the UI is, in its "Model training" view: the experiment list, or an experiment's runs
    page (in jt's saved view of the key metrics with ``view``)."""
    if experiment_id is None:
        return f"http://127.0.0.1:{port}/#/experiments?{MODEL_TRAINING}"
    share = f"&viewStateShareKey={VIEW_KEY}" if view else ""
    return f"http://127.0.0.1:{port}/#/experiments/{experiment_id}/runs?{MODEL_TRAINING}{share}"


def view_columns(key_metrics: Sequence[str]) -> list[str]:
    """The runs table's columns of jt's view: the key metrics, then ``best_<key>`` (what a search's
    outer run logs); the UI leaves out a column no run of the experiment has."""
    keys = dict.fromkeys([*key_metrics, *(f"best_{k}" for k in key_metrics)])
    return [f"metrics.`{k}`" for k in keys]


def view_value(key_metrics: Sequence[str], created_ms: Optional[int] = None) -> str:
    """The value of ``VIEW_TAG``: MLflow's saved-view envelope (name, times, the view state as JSON:
    the selected columns and their order after run name, start time and duration), and the columns
    under ``jt`` (what tells a view jt wrote from one the user saved over it in the UI)."""
    cols = view_columns(key_metrics)
    now = int(time.time() * 1000)
    state = {"selectedColumns": cols, "columnOrder": ["attributes.`Run Name`", "runDateAndNestInfo", "duration", *cols]}
    return json.dumps({"name": VIEW_NAME, "createdAt": created_ms or now, "updatedAt": now,
                       "state": json.dumps(state), "jt": cols})


def experiment_tags(key_metrics: Sequence[str]) -> dict[str, str]:
    """The tags that file a jt experiment as model training and give it jt's view of its key metrics."""
    tags = {KIND_TAG: KIND}
    if key_metrics:
        tags[VIEW_TAG] = view_value(key_metrics)
    return tags


def _refreshed_view(have: Optional[str], key_metrics: Sequence[str]) -> Optional[str]:
    """The view tag to write over ``have`` (None: leave it): a new one where there is none, jt's own
    one again where the key metrics changed; a view the user saved over it is the user's."""
    if not key_metrics:
        return None
    if have is None:
        return view_value(key_metrics)
    try:
        old = json.loads(have)
    except ValueError:
        return None
    if not isinstance(old, dict) or "jt" not in old or old["jt"] == view_columns(key_metrics):
        return None
    return view_value(key_metrics, old.get("createdAt") if isinstance(old.get("createdAt"), int) else None)


def _key_metrics(task: str) -> tuple[str, ...]:
    from toolkit import plugins

    try:
        return tuple(getattr(plugins.load("task", task), "key_metrics", ()))
    except Exception:  # noqa: BLE001 - a task whose plugin is gone: its experiment gets no view
        return ()


def prepare(root: Path) -> list[tuple[str, str, bool]]:
    """Tag the jt experiments of the store at ``root`` for the UI (idempotent; ~0.2 s, loading the
    task plugins for their key metrics): the experiment kind where it is missing, jt's view where it
    is missing or jt's own is out of date.

    Written in ``mlflow.db`` directly (the ``experiment_tags`` table MLflow keeps its experiment
    tags in), so ``jt ui`` starts without importing MLflow.

    Returns:
        ``(experiment id, name, has jt's view)`` of each active jt experiment (the tag ``jt.task``),
        the one with the newest run first; ``[]`` where the database cannot be read so.
    """
    out = []
    try:
        con = sqlite3.connect(root / "mlflow.db", timeout=30)
    except sqlite3.Error:
        return out
    try:
        with con:
            rows = con.execute(
                "SELECT e.experiment_id, e.name, t.value FROM experiments e JOIN experiment_tags t "
                "ON t.experiment_id = e.experiment_id AND t.key = 'jt.task' WHERE e.lifecycle_stage = 'active' "
                "ORDER BY (SELECT MAX(r.start_time) FROM runs r WHERE r.experiment_id = e.experiment_id) DESC, "
                "e.experiment_id").fetchall()
            for eid, name, task in rows:
                con.execute("INSERT OR IGNORE INTO experiment_tags (key, value, experiment_id) VALUES (?, ?, ?)",
                            (KIND_TAG, KIND, eid))
                have = con.execute("SELECT value FROM experiment_tags WHERE key = ? AND experiment_id = ?",
                                   (VIEW_TAG, eid)).fetchone()
                value = _refreshed_view(have[0] if have else None, _key_metrics(str(task)))
                if value is not None:
                    con.execute("INSERT OR REPLACE INTO experiment_tags (key, value, experiment_id) VALUES (?, ?, ?)",
                                (VIEW_TAG, value, eid))
                out.append((str(eid), str(name), have is not None or value is not None))
    except sqlite3.Error:
        return []
    finally:
        con.close()
    return out


def _app_installed() -> bool:
    """Whether jt's ``mlflow.app`` entry point is installed (an install older than it lacks it)."""
    from importlib.metadata import entry_points

    return any(e.name == APP_NAME for e in entry_points(group="mlflow.app"))


def command(root: Path, port: int) -> tuple[list[str], dict[str, str]]:
    """The ``mlflow ui`` command line and environment for the store at ``root``: one worker, no job
    runners, no telemetry, jt's app (``toolkit.store.ui_app``) where it is installed."""
    cmd = [sys.executable, "-m", "mlflow", "ui", "--backend-store-uri", f"sqlite:///{root / 'mlflow.db'}",
           "--default-artifact-root", str(root / "runs"), "--host", "127.0.0.1", "--port", str(port),
           "--workers", "1"]
    if _app_installed():
        cmd += ["--app-name", APP_NAME]
    env = {**os.environ, "MLFLOW_SERVER_ENABLE_JOB_EXECUTION": "false"}
    env.setdefault("MLFLOW_DISABLE_TELEMETRY", "true")
    env.setdefault("DO_NOT_TRACK", "true")
    return cmd, env


def open_when_up(target: str, port: int, timeout_s: float = 120.0) -> None:
    """Open ``target`` in a browser once the server on ``port`` answers ``/health`` (in a thread:
    ``serve`` goes on); a line on stderr where no browser can be opened."""
    import threading
    import urllib.request
    import webbrowser

    def wait_and_open() -> None:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/health", timeout=2) as r:
                    if r.status == 200:
                        break
            except OSError:
                time.sleep(0.3)
        else:
            return
        if not webbrowser.open(target):
            print("jt: no browser to open here; open the URL above", file=sys.stderr)

    threading.Thread(target=wait_and_open, daemon=True).start()


def check_port(port: Any) -> None:
    """One ``JtError`` line unless ``port`` is a TCP port (1-65535) free on 127.0.0.1.

    The port is bound for a moment as uvicorn will bind it (``SO_REUSEADDR``: a port that only
    has connections closing in ``TIME_WAIT`` is free).
    """
    if isinstance(port, bool) or not isinstance(port, int) or not 1 <= port <= 65535:
        raise JtError(f"--port {port}: a TCP port is a whole number from 1 to 65535 (5000 by default)")
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind(("127.0.0.1", port))
        except OSError as e:
            why = "already in use (another jt ui or server?)" if e.errno == errno.EADDRINUSE else e.strerror
            raise JtError(f"--port {port}: 127.0.0.1:{port} is {why}; choose another with --port") from None


def _loopback(host: str) -> bool:
    host = host.strip().strip("[]")
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False  # a name (it may resolve anywhere), an empty host (every interface), ...


def _bind_host(value: str) -> Optional[str]:
    """The host of a gunicorn bind ``HOST:PORT`` / ``[V6]:PORT`` / ``HOST``; None for a UNIX socket
    (``unix:PATH``); ``fd://N`` gives ``"fd://N"`` (a socket bound who knows where)."""
    if value.startswith("unix:"):
        return None
    if value.startswith("fd://"):
        return value
    if value.startswith("["):
        return value[1:].split("]", 1)[0]
    return value.rsplit(":", 1)[0] if value.count(":") == 1 else value


def _opt_values(args: list[str], long: str, short: Optional[str] = None) -> list[str]:
    """Every value of option ``long`` (``--long V``, ``--long=V``) or ``short`` (``-s V``, ``-sV``)."""
    out = []
    for i, a in enumerate(args):
        nxt = args[i + 1] if i + 1 < len(args) else ""
        if a == long or (short and a == short):
            out.append(nxt)
        elif a.startswith(long + "="):
            out.append(a.split("=", 1)[1])
        elif short and a.startswith(short) and not a.startswith("--") and len(a) > len(short):
            out.append(a[len(short):].lstrip("="))
    return out


def check_env(env: Optional[Mapping[str, str]] = None) -> None:
    """One ``JtError`` line when the environment would make MLflow's server listen beyond loopback.

    jt passes ``--host 127.0.0.1``, which wins over ``MLFLOW_HOST`` and ``UVICORN_HOST``. What it
    cannot override: a gunicorn bind (``-b`` / ``--bind``) in ``MLFLOW_GUNICORN_OPTS`` or
    ``GUNICORN_CMD_ARGS`` (gunicorn listens on every bind it is given), a socket inherited by file
    descriptor (``--fd`` in ``MLFLOW_UVICORN_OPTS``, ``UVICORN_FD``, a ``fd://`` bind); and a
    ``--host`` in ``MLFLOW_UVICORN_OPTS`` asks for another interface in so many words. Each of
    these is refused unless it names a loopback address (``127.0.0.0/8``, ``::1``, ``localhost``)
    or a UNIX socket.

    Args:
        env: the environment the server would inherit (``os.environ`` by default).

    Raises:
        JtError: naming the variable and the setting, and what to do.
    """
    env = os.environ if env is None else env
    fix = "jt ui serves on 127.0.0.1 only; unset it (a shared server is `mlflow server`, docs/cluster.md)"
    for var in OPTION_VARIABLES:
        text = env.get(var, "")
        if not text.strip():
            continue
        try:
            args = shlex.split(text)
        except ValueError:
            raise JtError(f"{var}={text!r} cannot be parsed as options (unbalanced quotes); {fix}") from None
        binds = _opt_values(args, "--bind", "-b") if var != "MLFLOW_UVICORN_OPTS" else \
            _opt_values(args, "--host")
        for b in binds:
            host = _bind_host(b) if var != "MLFLOW_UVICORN_OPTS" else b
            if host is not None and not _loopback(host):
                raise JtError(f"{var} makes MLflow's server listen on {b or '(every interface)'}; {fix}")
        if var == "MLFLOW_UVICORN_OPTS" and (_opt_values(args, "--fd")):
            raise JtError(f"{var} hands MLflow's server a socket by file descriptor (--fd); {fix}")
    if env.get("UVICORN_FD", "").strip():
        raise JtError(f"UVICORN_FD={env['UVICORN_FD']} hands MLflow's server a socket by file descriptor; {fix}")


def check(root: Path, port: Any, env: Optional[Mapping[str, str]] = None) -> None:
    """Everything ``serve`` refuses, as one ``JtError`` line, before MLflow starts: the port
    (``check_port``), the environment (``check_env``) and the store (``check_root``)."""
    from toolkit.store.tracking import check_root

    check_port(port)
    check_env(env)
    check_root(root)  # a file, or an mlflow.db that is not SQLite: one line, before MLflow's traceback


def ensure_store(root: Path) -> None:
    """Create the store at ``root`` where it has no database yet (through ``Store``: the schema,
    MLflow's "Default" experiment inside the store); an existing one is left as it is, without
    importing MLflow, which saves seconds."""
    if not (root / "mlflow.db").is_file():
        from toolkit.store.opening import open_store

        open_store(root)


def serve(root: Path, port: int) -> int:
    """Run the UI for the store at ``root`` until Ctrl-C or SIGTERM (which stop the server too;
    so does a ``kill -9`` of jt, through ``toolkit.store.ui_guard``).

    A store that has no database yet is created first (``ensure_store``).

    Returns:
        The server's exit status (0 after Ctrl-C / SIGTERM).

    Raises:
        JtError: what ``check`` refuses.
    """
    check(root, port)
    ensure_store(root)
    cmd, env = command(root, port)
    # its own process group, led by the guard (toolkit.store.ui_guard): stopping jt stops MLflow's
    # server process and its worker together, also where a shell started jt in the background
    # (SIGINT ignored there), and the guard stops them when jt dies without a word (kill -9)
    guard = [sys.executable, "-m", "toolkit.store.ui_guard", str(os.getpid()), *cmd]
    proc = subprocess.Popen(guard, env=env, start_new_session=True)

    def stop(signum: int, frame: Any) -> None:
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGTERM, stop)
    try:
        return proc.wait()
    except KeyboardInterrupt:
        for sig, wait_s in ((signal.SIGTERM, 15.0), (signal.SIGKILL, 5.0)):
            try:
                os.killpg(proc.pid, sig)
            except ProcessLookupError:
                break
            try:
                proc.wait(timeout=wait_s)
                break
            except subprocess.TimeoutExpired:
                continue
        return 0
    finally:
        signal.signal(signal.SIGTERM, old)
