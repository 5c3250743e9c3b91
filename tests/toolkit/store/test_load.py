"""Under load (issue 55): four runs and ``jt ui`` on one store at once all finish with every metric
and artifact intact — on a local store, and (slow) against an MLflow tracking server.

Two seeds, each run twice at once: a pair of runs with one seed must end identical (every metric
of every run and nested run, the same artifact files), so a write lost or garbled by the
contention fails the test. Real ``jt run`` processes, a real ``jt ui`` polled over HTTP on
127.0.0.1, a real SQLite store; bounded in time.
"""

from __future__ import annotations

import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from tests.conftest import jt_env
from tests.plugins.jt_executors.ray_cluster import free_port

RUN = ["task=zdt1", "experiment=smoke", "search=random"]  # 60 nested evaluations each
TIMING = ("eval_seconds", "wall_s", "seconds")  #: metrics that measure time, not the result
SEEDS = (0, 0, 1, 1)
LIMIT_S = 240.0


def _start(store: str, seed: int) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "toolkit.cli", "run", *RUN, f"seed={seed}", f"store={store}"],
                            env=jt_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _run_ids(said: str) -> str:
    """The run id in ``jt: run <id> (task); store ...``."""
    return next(line.split()[2] for line in said.splitlines() if line.startswith("jt: run "))


def _contents(store: Path | str, run_id: str) -> tuple:
    """Every metric (key, value, step) of the run and its nested runs, by nested run name, and the
    names of their artifact files."""
    from toolkit.store.opening import open_store

    s = open_store(store)
    client = s.client
    run = client.get_run(run_id)
    kids = client.search_runs([run.info.experiment_id], f"tags.mlflow.parentRunId = '{run_id}'", max_results=1000)
    out = []
    for r in [run, *kids]:
        metrics = sorted((k, client.get_metric_history(r.info.run_id, k)) for k in r.data.metrics
                         if not any(t in k for t in TIMING))
        values = [(k, [(m.value, m.step) for m in hist]) for k, hist in metrics]
        files = sorted(a.path for a in client.list_artifacts(r.info.run_id))
        out.append((r.info.run_name if r is not run else "outer", r.info.status, values, files))
    return tuple(sorted(out, key=lambda x: x[0]))


def _load(store: str, ui_port: int | None) -> dict[int, list[tuple]]:
    procs = [(seed, _start(store, seed)) for seed in SEEDS]
    t0, polls = time.monotonic(), 0
    try:
        while any(p.poll() is None for _, p in procs):
            assert time.monotonic() - t0 < LIMIT_S, "the runs did not finish in time"
            if ui_port is not None:  # the UI answers while the runs write
                url = f"http://127.0.0.1:{ui_port}/ajax-api/2.0/mlflow/experiments/search?max_results=10"
                try:
                    with urllib.request.urlopen(url, timeout=5) as r:
                        polls += r.status == 200
                except OSError:
                    pass
            time.sleep(0.5)
    finally:
        for _, p in procs:
            if p.poll() is None:
                p.kill()
    by_seed: dict[int, list[tuple]] = {}
    for seed, p in procs:
        out, err = p.communicate()
        assert p.returncode == 0, err[-2000:]
        by_seed.setdefault(seed, []).append(_contents(store, _run_ids(out + err)))
    if ui_port is not None:
        assert polls > 0, "jt ui never answered while the runs wrote"
    return by_seed


def _check(by_seed: dict[int, list[tuple]]) -> None:
    for seed, (a, b) in by_seed.items():
        assert a[0][1] == "FINISHED" and len(a) > 1, (seed, a[0][:2])
        assert all(r[1] == "FINISHED" for r in a), seed
        assert all(r[2] for r in a), "a run without metrics"
        assert a == b, f"seed {seed}: two runs of one seed differ after running side by side"
    assert by_seed[0] != by_seed[1]  # the comparison can tell runs apart


def test_four_runs_and_the_ui_on_one_local_store(tmp_path):
    store = tmp_path / "store"
    port = free_port()
    ui = subprocess.Popen([sys.executable, "-m", "toolkit.cli", "ui", f"store={store}", "--port", str(port)],
                          env=jt_env(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        _check(_load(str(store), port))
    finally:
        import os
        import signal

        os.killpg(ui.pid, signal.SIGTERM)
        ui.wait(timeout=60)


@pytest.mark.slow
def test_four_runs_on_one_mlflow_server_store(tmp_path):
    from tests.toolkit.store.mlflow_server import MlflowServer

    with MlflowServer(tmp_path / "server") as server:
        _check(_load(server.uri, None))
