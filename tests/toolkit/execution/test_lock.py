"""The run lock: refused while a live process holds it, free once that process dies (kill -9), and not
kept alive by a process the owner forked (pool workers outliving their driver for a moment)."""

import os
import signal
import socket
import subprocess
import sys
import textwrap
import time

import pytest

from toolkit.errors import JtError
from toolkit.execution.lock import RunLock

HOLD = textwrap.dedent("""
    import os, sys, time
    from toolkit.execution.lock import RunLock
    lock = RunLock(sys.argv[1], "r1").acquire()
    child = os.fork() if sys.argv[2] == "fork" else 1
    if child == 0:  # a child that outlives its parent
        time.sleep(60)
        os._exit(0)
    print("held", child, flush=True)
    time.sleep(60)
""")


def _holder(tmp_path, mode="plain"):
    """A process holding the lock (``mode="fork"``: and a child it forked); ``(process, child pid)``."""
    proc = subprocess.Popen([sys.executable, "-c", HOLD, str(tmp_path), mode], stdout=subprocess.PIPE, text=True)
    word, child = proc.stdout.readline().split()
    assert word == "held"
    return proc, int(child) if mode == "fork" else None


def test_a_live_owner_is_named_in_one_line(tmp_path):
    proc, _ = _holder(tmp_path)
    try:
        with pytest.raises(JtError) as e:
            RunLock(tmp_path, "r1").acquire("/some/store")
        msg = str(e.value)
        assert "\n" not in msg and msg.startswith(f"run r1 is already being run by pid {proc.pid} on "
                                                  f"{socket.gethostname()} (since ")
        assert msg.endswith("jt run resume=r1 store=/some/store")
    finally:
        proc.kill()
        proc.wait()


@pytest.mark.parametrize("mode", ["plain", "fork"])
def test_a_dead_owner_blocks_nothing(tmp_path, mode):
    proc, child = _holder(tmp_path, mode)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    try:
        _acquire_after(tmp_path)
    finally:
        if child:
            os.kill(child, signal.SIGKILL)


def _acquire_after(tmp_path):
    lock = RunLock(tmp_path, "r1")
    deadline = time.time() + 10
    while True:  # the kernel drops the lock with its process (a forked child keeps none)
        try:
            lock.acquire()
            break
        except JtError:
            assert time.time() < deadline, "the lock outlived its owner"
            time.sleep(0.05)
    assert lock.held
    lock.release()
    assert not lock.held
    with RunLock(tmp_path, "r1") as again:  # released: free for the next owner
        assert again.held
