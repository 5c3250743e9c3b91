"""The guard between ``jt ui`` and MLflow's server: the server never outlives jt, even a ``kill -9``.

``jt ui`` starts ``python -m toolkit.store.ui_guard JT_PID CMD...`` in a session of its own; the
guard starts ``CMD`` (MLflow's server, which starts its uvicorn worker) in its process group and
waits. It stops the whole group, SIGTERM first and SIGKILL after ``STOP_S`` seconds, when

* it gets SIGTERM (``jt ui`` stopping on Ctrl-C or its own SIGTERM), or
* ``jt ui`` is gone: its parent is no longer ``JT_PID`` (looked at every ``PERIOD_S`` seconds;
  a ``kill -9`` of jt runs no handler of jt's, so only a process of the group can notice).

When the server exits on its own, the guard exits with its status. Standard library only, so it
starts in a few milliseconds.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys

#: seconds between two looks at whether jt is still the parent
PERIOD_S = 0.5
#: seconds the server gets to stop after SIGTERM before its group is SIGKILLed
STOP_S = 15.0


def _stop_group(child: subprocess.Popen) -> None:
    """SIGTERM the group (the guard ignores it), wait up to ``STOP_S`` for the server, then
    SIGKILL whatever is left of the group (a worker that outlived it), the guard with it."""
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    try:
        os.killpg(0, signal.SIGTERM)
    except ProcessLookupError:  # pragma: no cover - the guard itself is in the group
        pass
    try:
        child.wait(timeout=STOP_S)
    except subprocess.TimeoutExpired:
        pass
    os.killpg(0, signal.SIGKILL)  # the last act: nothing of the group keeps the port


def main(argv: list[str]) -> int:
    """Run ``CMD`` until it exits, jt goes or a SIGTERM comes (run as its own process only: it
    signals its whole process group when it stops).

    Args:
        argv: ``[JT_PID, CMD...]``.

    Returns:
        The server's exit status; 2 for a bad command line. A stop ends in SIGKILL of the group.
    """
    if len(argv) < 2 or not argv[0].isdigit():
        print("usage: python -m toolkit.store.ui_guard JT_PID CMD...", file=sys.stderr)
        return 2
    parent, cmd = int(argv[0]), argv[1:]
    stopping: list[int] = []
    signal.signal(signal.SIGTERM, lambda signum, frame: stopping.append(signum))
    child = subprocess.Popen(cmd)
    while True:
        try:
            return child.wait(timeout=PERIOD_S)
        except subprocess.TimeoutExpired:
            pass
        if stopping or os.getppid() != parent:
            _stop_group(child)
            return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
