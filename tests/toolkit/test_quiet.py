"""No native banner reaches the terminal: ``toolkit.quiet.preload_quietly`` in the CLI's working
commands and in every worker process of the local executor (issue 31, "quiet workers")."""

from __future__ import annotations

import subprocess
import sys
import textwrap

BANNER = "pybullet build time"

WORKERS = textwrap.dedent("""
    from omegaconf import OmegaConf
    from toolkit import plugins

    class Probe:
        def __init__(self, k):
            import pybullet  # a worker's first import, as an env's simulator does it
            self.k = k
        def ping(self):
            return self.k

    if __name__ == "__main__":
        ex = plugins.load("executor", "local")(OmegaConf.create({"name": "local", "workers": 2,
                                                                   "start_method": "spawn"}))
        group = ex.actors(Probe, [(0,), (1,)])
        print("pings", group.call("ping"))
        group.close()
        ex.close()
""")


def test_worker_processes_print_no_banner(tmp_path):
    script = tmp_path / "workers.py"
    script.write_text(WORKERS)
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert "pings [0, 1]" in out.stdout
    assert BANNER not in out.stdout + out.stderr


def test_the_banner_is_there_without_the_preload(tmp_path):
    """The check above can fail: a plain import in a fresh process prints the banner."""
    out = subprocess.run([sys.executable, "-c", "import pybullet"], capture_output=True, text=True, timeout=60)
    assert BANNER in out.stdout + out.stderr


def test_a_run_prints_no_banner(tmp_path):
    out = subprocess.run(["jt", "run", "task=spd_tracking", "experiment=smoke", f"store={tmp_path / 's'}"],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert BANNER not in out.stdout + out.stderr


def test_the_cost_comes_before_a_prior_is_trained(tmp_path):
    """experiment=laptop for task=getup on an empty store: the cost line is the first thing said,
    before the C-VAE prior's training starts (the process is stopped there)."""
    import os
    import signal

    p = subprocess.Popen(["jt", "run", "task=getup", "experiment=laptop", f"store={tmp_path / 's'}"],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True)
    lines = []
    try:
        for line in p.stdout:
            lines.append(line.rstrip())
            if line.startswith("jt: action.prior") or len(lines) > 20:
                break
    finally:
        os.killpg(p.pid, signal.SIGKILL)
        p.wait(timeout=30)
    said = [ln for ln in lines if ln.startswith("jt:")]
    assert said and said[0].startswith("jt: cost: ~"), lines
    assert any(ln.startswith("jt: action.prior=auto: no cvae prior") for ln in said[1:]), lines
    assert not any(BANNER in ln for ln in lines)
