"""``jt ui``: MLflow's UI on a folder store, started lean (one worker, no job runners).

MLflow's server by default starts 4 uvicorn workers and a set of job runners (for its GenAI
features, which jt does not use): ~30 s to come up on two cores. One worker and no jobs serve
a researcher's browser as well and are up in a few seconds.

It listens on 127.0.0.1 only (the store's runs, params and files are not for the network; a
tracking server is ``mlflow server``, docs/cluster.md). A ``--port`` out of range or already in
use, or an environment variable MLflow or its web server would read to listen elsewhere, is one
``JtError`` line before MLflow starts (``check``).
"""

from __future__ import annotations

import errno
import ipaddress
import os
import shlex
import signal
import socket
import subprocess
import sys
from pathlib import Path
from typing import Any, Mapping, Optional

from toolkit.errors import JtError

#: environment variables holding server options MLflow forwards (``mlflow server --gunicorn-opts``
#: / ``--uvicorn-opts``) or that gunicorn reads itself; a bind in one is checked by ``check_env``
OPTION_VARIABLES = ("MLFLOW_GUNICORN_OPTS", "MLFLOW_UVICORN_OPTS", "GUNICORN_CMD_ARGS")


def url(port: int) -> str:
    """Where the UI is, opening in its "Model training" view (MLflow 3 starts in GenAI's otherwise)."""
    return f"http://127.0.0.1:{port}/#/experiments?workflowType=machine_learning"


def command(root: Path, port: int) -> tuple[list[str], dict[str, str]]:
    """The ``mlflow ui`` command line and environment for the store at ``root``."""
    cmd = [sys.executable, "-m", "mlflow", "ui", "--backend-store-uri", f"sqlite:///{root / 'mlflow.db'}",
           "--default-artifact-root", str(root / "runs"), "--host", "127.0.0.1", "--port", str(port),
           "--workers", "1"]
    return cmd, {**os.environ, "MLFLOW_SERVER_ENABLE_JOB_EXECUTION": "false"}


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


def serve(root: Path, port: int) -> int:
    """Run the UI for the store at ``root`` until Ctrl-C or SIGTERM (which stop the server too;
    so does a ``kill -9`` of jt, through ``toolkit.store.ui_guard``).

    A store that has no database yet is created first (through ``Store``: the schema, MLflow's
    "Default" experiment inside the store); an existing one is served without importing MLflow
    here, which saves seconds.

    Returns:
        The server's exit status (0 after Ctrl-C / SIGTERM).

    Raises:
        JtError: what ``check`` refuses.
    """
    check(root, port)
    if not (root / "mlflow.db").is_file():
        from toolkit.store.opening import open_store

        open_store(root)
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
