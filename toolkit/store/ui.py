"""``jt ui``: MLflow's UI on a folder store, started lean (one worker, no job runners).

MLflow's server by default starts 4 uvicorn workers and a set of job runners (for its GenAI
features, which jt does not use): ~30 s to come up on two cores. One worker and no jobs serve
a researcher's browser as well and are up in a few seconds.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any


def url(port: int) -> str:
    """Where the UI is, opening in its "Model training" view (MLflow 3 starts in GenAI's otherwise)."""
    return f"http://127.0.0.1:{port}/#/experiments?workflowType=machine_learning"


def command(root: Path, port: int) -> tuple[list[str], dict[str, str]]:
    """The ``mlflow ui`` command line and environment for the store at ``root``."""
    cmd = [sys.executable, "-m", "mlflow", "ui", "--backend-store-uri", f"sqlite:///{root / 'mlflow.db'}",
           "--default-artifact-root", str(root / "runs"), "--host", "127.0.0.1", "--port", str(port),
           "--workers", "1"]
    return cmd, {**os.environ, "MLFLOW_SERVER_ENABLE_JOB_EXECUTION": "false"}


def serve(root: Path, port: int) -> int:
    """Run the UI for the store at ``root`` until Ctrl-C or SIGTERM (which stop the server too).

    A store that has no database yet is created first (through ``Store``: the schema, MLflow's
    "Default" experiment inside the store); an existing one is served without importing MLflow
    here, which saves seconds.

    Returns:
        The server's exit status (0 after Ctrl-C / SIGTERM).
    """
    from toolkit.store.tracking import check_root

    check_root(root)  # a file, or an mlflow.db that is not SQLite: one line, before MLflow's traceback
    if not (root / "mlflow.db").is_file():
        from toolkit.store.tracking import Store

        Store(root)
    cmd, env = command(root, port)
    # its own process group: stopping jt stops MLflow's server process and its worker together,
    # also where a shell started jt in the background (SIGINT ignored there)
    proc = subprocess.Popen(cmd, env=env, start_new_session=True)

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
