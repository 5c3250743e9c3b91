"""jt ui as a browser shows it (-m slow; needs Debian's ``chromium``, skipped without it): a real
``jt run`` into a new store, ``jt ui`` on it, and headless Chromium (a fresh profile, as a first
visit) on the URL jt printed and on one of its runs. The page at the printed URL is the task's runs
table with its key metrics as columns (jt's saved view); a run's page is in "Model training", not
GenAI's "Evaluation runs", though its URL names no view.

By hand (what made docs/img/store_ui_runs.png):

    jt run task=highjump search=bds experiment=smoke store=/tmp/uistore
    jt ui store=/tmp/uistore --port 5077 &          # prints each task's URL
    chromium --headless --no-sandbox --disable-gpu --window-size=1400,900 --virtual-time-budget=15000 \\
        --screenshot=runs.png "URL jt printed"
"""

import re
import shutil
import signal
import subprocess
import sys
import time
import urllib.request

import pytest

from tests.conftest import jt_env, run_jt
from tests.plugins.jt_executors.ray_cluster import free_port

pytestmark = [pytest.mark.slow, pytest.mark.skipif(shutil.which("chromium") is None,
                                                   reason="no chromium (apt-get install chromium)")]


def _dom(url, profile):
    """The page's DOM after 15 s of its (virtual) time, in a fresh Chromium profile."""
    out = subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                          "--disable-background-networking", f"--user-data-dir={profile}", "--window-size=1400,900",
                          "--virtual-time-budget=15000", "--dump-dom", url],
                         capture_output=True, text=True, timeout=120)
    return out.stdout


def test_the_printed_url_shows_the_key_metrics_in_model_training(tmp_path):
    store = tmp_path / "s"
    done = run_jt("run", "task=spd_tracking", "experiment=smoke", f"store={store}", timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    run_id = re.search(r"run ([0-9a-f]{32}) FINISHED", done.stdout).group(1)
    port = free_port()
    proc = subprocess.Popen([sys.executable, "-m", "toolkit.cli", "ui", f"store={store}", "--port", str(port)],
                            env=jt_env(), stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        proc.stdout.readline()  # "MLflow UI for ... (Ctrl-C to stop):"
        name, url = proc.stdout.readline().split()
        assert name == "spd_tracking" and url.endswith("?workflowType=machine_learning&viewStateShareKey=jt")
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            try:
                urllib.request.urlopen(f"http://127.0.0.1:{port}/health", timeout=2)
                break
            except OSError:
                time.sleep(0.3)
        runs = _dom(url, tmp_path / "p1")
        for key in ("fps", "spd_share_pct", "err_mean_dt30", "err_mean_dt600", "n_diverged"):
            assert f'col-id="metrics.`{key}`"' in runs, key
        assert "spd_tracking·single·seed0" in runs
        experiment = url.split("/experiments/")[1].split("/")[0]
        run_page = _dom(f"http://127.0.0.1:{port}/#/experiments/{experiment}/runs/{run_id}", tmp_path / "p2")
        assert "spd_tracking·single·seed0" in run_page and "Model metrics" in run_page
        assert "Evaluation runs" not in run_page  # GenAI's side bar: not there
    finally:
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=30)
