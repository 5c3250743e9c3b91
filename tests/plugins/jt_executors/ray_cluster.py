"""A real Ray cluster on this machine for tests: ``ray start --head`` plus more ``ray start`` nodes.

Every node is started in its own session (``start_new_session``), so teardown ends exactly the
processes this cluster started (its raylets, GCS, agents and workers), found by session id, and
never touches another Ray on the machine (``ray stop`` would: it ends every Ray by name).
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Optional

RAY = str(Path(sys.executable).with_name("ray"))
DRIVER_ENV = {"RAY_USAGE_STATS_ENABLED": "0", "RAY_AUTH_MODE": "disabled"}
"""Environment of the nodes and of a driver connecting to them. Token authentication is off
explicitly: Ray >= 2.5x turns it on by itself once ``~/.ray/auth_token`` exists (a local
``ray.init()`` writes one), and then a node or driver without the token cannot join."""


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def session_of(pid: int) -> Optional[int]:
    """The session id of process ``pid`` (None if it is gone or a zombie)."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            fields = fh.read().rsplit(")", 1)[1].split()
        return None if fields[0] == "Z" else int(fields[3])
    except (OSError, IndexError, ValueError):
        return None


def cmdline(pid: int) -> str:
    """The command line of ``pid`` ('' if it is gone)."""
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as fh:
            return fh.read().replace(b"\0", b" ").decode(errors="replace").strip()
    except OSError:
        return ""


def session_pids(sessions: list[int]) -> list[int]:
    """Every live process in one of ``sessions``."""
    return [int(n) for n in os.listdir("/proc") if n.isdigit() and session_of(int(n)) in sessions]


def end_sessions(sessions: list[int], term_s: float = 3.0) -> None:
    """SIGTERM every process of ``sessions`` (processes this test started, each in its own
    session), wait up to ``term_s``, then SIGKILL what is left."""
    for sig, wait in ((signal.SIGTERM, term_s), (signal.SIGKILL, 2.0)):
        for p in session_pids(sessions):
            try:
                os.kill(p, sig)
            except ProcessLookupError:
                pass
        deadline = time.monotonic() + wait
        while session_pids(sessions) and time.monotonic() < deadline:
            time.sleep(0.2)


def node_of(seconds: float) -> str:
    """The id of the Ray node running this after ``seconds`` (a task for ``executor.map``)."""
    import ray

    time.sleep(seconds)
    return ray.get_runtime_context().get_node_id()


class LocalRayCluster:
    """``nodes`` Ray nodes of ``cpus`` CPUs each, joined into one cluster on 127.0.0.1.

    Args:
        nodes: number of nodes (the first is the head).
        cpus: CPUs each node offers.
        env: extra environment of the nodes (and so of their workers), e.g. ``PYTHONPATH``.
    """

    def __init__(self, nodes: int = 2, cpus: int = 1, env: Optional[dict] = None) -> None:
        self.nodes, self.cpus = nodes, cpus
        self.env = {**os.environ, **DRIVER_ENV, **(env or {})}
        # a short private folder: Ray's socket paths must stay under the 107-byte limit
        self.temp = Path(tempfile.mkdtemp(prefix="jtray-"))
        self.port = free_port()
        self.address = f"127.0.0.1:{self.port}"
        self.sessions: list[int] = []
        self.log = self.temp / "start.log"

    def _start(self, args: list[str]) -> None:
        common = ["--num-cpus", str(self.cpus), "--temp-dir", str(self.temp), "--disable-usage-stats",
                  "--node-ip-address", "127.0.0.1", "--object-store-memory", str(100 * 1024 ** 2),
                  "--dashboard-agent-listen-port", str(free_port()),
                  "--metrics-export-port", str(free_port()),
                  "--runtime-env-agent-port", str(free_port())]
        with open(self.log, "a") as log:
            proc = subprocess.Popen([RAY, "start", *args, *common], env=self.env, stdout=log,
                                    stderr=subprocess.STDOUT, start_new_session=True)
            self.sessions.append(proc.pid)  # its session id: the daemons it leaves keep it
            rc = proc.wait(timeout=120)
        if rc != 0:
            raise RuntimeError(f"ray start failed ({rc}):\n{self.log.read_text()[-6000:]}")

    def start(self) -> "LocalRayCluster":
        """Start the head, then the other nodes; returns self once every node has joined."""
        try:
            self._start(["--head", "--port", str(self.port), "--include-dashboard", "false",
                         "--ray-client-server-port", str(free_port())])
            for _ in range(self.nodes - 1):
                self._start(["--address", self.address])
        except BaseException:
            self.stop()
            raise
        return self

    def pids(self) -> list[int]:
        """Every live process of this cluster."""
        return session_pids(self.sessions)

    def workers(self, title: str) -> list[int]:
        """Worker processes whose title starts with ``title`` (e.g. ``ray::jt_evaluate``)."""
        return [p for p in self.pids() if cmdline(p).startswith(title)]

    def stop(self) -> None:
        """End every process of this cluster (TERM, then KILL) and remove its folder."""
        end_sessions(self.sessions)
        shutil.rmtree(self.temp, ignore_errors=True)

    def __enter__(self) -> "LocalRayCluster":
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
