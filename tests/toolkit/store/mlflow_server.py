"""A real ``mlflow server`` on 127.0.0.1 for tests: SQLite backend, artifacts served by it.

Started in its own session and ended by session id (TERM, then KILL), so teardown ends exactly
the processes it started. MLflow's job runner (seven extra processes) is switched off.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

from tests.plugins.jt_executors.ray_cluster import end_sessions, free_port

MLFLOW = str(Path(sys.executable).with_name("mlflow"))


class MlflowServer:
    """``mlflow server --backend-store-uri sqlite:///<folder>/mlflow.db --artifacts-destination
    <folder>/artifacts --serve-artifacts --workers 1`` on a free port.

    Args:
        folder: where the database, the served artifacts and the log go.
        start_timeout_s: how long it may take to answer ``/health``.
    """

    def __init__(self, folder: Path, start_timeout_s: float = 120.0) -> None:
        self.folder = Path(folder)
        self.port = free_port()
        self.uri = f"http://127.0.0.1:{self.port}"
        self.artifacts = self.folder / "artifacts"
        self.log = self.folder / "server.log"
        self.start_timeout_s = start_timeout_s
        self.sessions: list[int] = []
        self.startup_s = float("nan")

    def healthy(self) -> bool:
        """Whether ``GET /health`` answers 200."""
        try:
            with urllib.request.urlopen(f"{self.uri}/health", timeout=2) as r:
                return r.status == 200
        except OSError:
            return False

    def start(self) -> "MlflowServer":
        """Start it and wait until it answers; returns self."""
        self.folder.mkdir(parents=True, exist_ok=True)
        cmd = [MLFLOW, "server", "--backend-store-uri", f"sqlite:///{self.folder / 'mlflow.db'}",
               "--artifacts-destination", str(self.artifacts), "--serve-artifacts",
               "--host", "127.0.0.1", "--port", str(self.port), "--workers", "1"]
        env = {**os.environ, "MLFLOW_SERVER_ENABLE_JOB_EXECUTION": "false"}
        t0 = time.monotonic()
        with open(self.log, "w") as log:
            proc = subprocess.Popen(cmd, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        self.sessions.append(proc.pid)
        try:
            while not self.healthy():
                if proc.poll() is not None or time.monotonic() - t0 > self.start_timeout_s:
                    raise RuntimeError(f"mlflow server did not start:\n{self.log.read_text()[-3000:]}")
                time.sleep(0.5)
        except BaseException:
            self.stop()
            raise
        self.startup_s = time.monotonic() - t0
        return self

    def stop(self) -> None:
        """End every process it started."""
        end_sessions(self.sessions)

    def __enter__(self) -> "MlflowServer":
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
