"""store=http://host:port: a real ``mlflow server`` (SQLite backend, served artifacts) on 127.0.0.1.

One server per module (~10-30 s to start). A smoke BDS search and a PPO training run through it on
a real two-node Ray cluster (``executor=ray``, evaluation folders shipped as if the workers shared
no filesystem with the driver; ``executor=local`` when Ray is not installed); every artifact lands
on the server and reads back by download, and ``jt show`` / ``jt ui`` work against it.
"""

from __future__ import annotations

import importlib.util
import time
from pathlib import Path

import pytest

from tests.conftest import run_jt
from tests.plugins.jt_executors.ray_cluster import DRIVER_ENV, LocalRayCluster, free_port
from tests.toolkit.store.mlflow_server import MlflowServer
from toolkit.config import compose
from toolkit.errors import JtError
from toolkit.execution.heartbeat import HEARTBEAT_TAG, OWNER_TAG, STALE_S, Heartbeat, check_not_owned
from toolkit.execution.runner import run
from toolkit.store import h5
from toolkit.store.opening import open_store
from toolkit.store.server import ServerStore, cache_root
from toolkit.store.tracking import Store, is_server_uri, store_root

HAVE_RAY = importlib.util.find_spec("ray") is not None


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    with MlflowServer(tmp_path_factory.mktemp("mlflow-server")) as s:
        yield s


@pytest.fixture(scope="module")
def executor():
    """``executor=ray`` overrides for a two-node cluster (shipping every file), else ``executor=local``."""
    if not HAVE_RAY:
        yield ["executor.workers=1"]
        return
    import ray

    with pytest.MonkeyPatch.context() as mp, LocalRayCluster(nodes=2, cpus=1) as c:
        for k, v in DRIVER_ENV.items():
            mp.setenv(k, v)
        try:
            yield ["executor=ray", f"executor.address={c.address}", "executor.ship_files=always"]
        finally:
            if ray.is_initialized():
                ray.shutdown()


@pytest.fixture(scope="module")
def runs(server, executor, tmp_path_factory):
    """A smoke BDS search and a smoke PPO training, each through the server and into a local store."""
    tmp = tmp_path_factory.mktemp("server-runs")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("JT_WORK_DIR", str(tmp / "cache"))
        out = {}
        for name, args in (("bds", ["task=strategy_landscape", "search=bds", "experiment=smoke", "seed=2"]),
                           ("ppo", ["task=highjump", "experiment=smoke", "agent.n_workers=2", "seed=1"])):
            t0 = time.monotonic()
            remote = run(compose([*args, *executor, f"store={server.uri}"]))
            seconds = time.monotonic() - t0
            local = run(compose([*args, "executor.workers=1", f"store={tmp / 'local'}"]))
            out[name] = (remote, local, seconds)
        yield out


def _tree(folder: Path) -> dict[str, int]:
    """``{relative path: size}`` of every file under ``folder``."""
    return {str(p.relative_to(folder)): p.stat().st_size for p in sorted(folder.rglob("*")) if p.is_file()}


def _with_children(store: Store, run_id: str) -> list:
    outer = store.get_run(run_id)
    kids = store.client.search_runs([outer.info.experiment_id], filter_string=f"tags.mlflow.parentRunId = '{run_id}'")
    return [outer, *sorted(kids, key=lambda r: int(r.data.tags["jt.eval_index"]))]


def test_uri_rules(tmp_path, monkeypatch):
    assert store_root("http://127.0.0.1:5000/") == "http://127.0.0.1:5000" and is_server_uri("https://h")
    assert store_root(str(tmp_path)) == tmp_path.resolve()
    monkeypatch.setenv("JT_STORE", "http://head:5000")
    assert store_root() == "http://head:5000"
    monkeypatch.setenv("JT_WORK_DIR", str(tmp_path / "w"))
    assert cache_root("http://head:5000") == (tmp_path / "w" / "head_5000").resolve()
    t0 = time.monotonic()
    with pytest.raises(JtError, match="no MLflow server answers there"):
        open_store(f"http://127.0.0.1:{free_port()}")
    assert time.monotonic() - t0 < 10
    monkeypatch.chdir(tmp_path)  # a local Store never takes a URI for a folder name
    with pytest.raises(ValueError, match="server URI"):
        Store("http://127.0.0.1:5000")
    assert not (tmp_path / "http:").exists()
    assert type(open_store(tmp_path / "local")) is Store and issubclass(ServerStore, Store)


@pytest.mark.parametrize("name", ["bds", "ppo"])
def test_every_artifact_lands_on_the_server(runs, server, name):
    remote, local, _ = runs[name]
    store = remote.store
    assert store.is_server and store.root == server.uri
    outers = _with_children(store, remote.run_id), _with_children(local.store, local.run_id)
    assert len(outers[0]) == len(outers[1])
    for r, l in zip(*outers):
        assert r.info.status == "FINISHED" and r.info.artifact_uri.startswith("mlflow-artifacts:")
        want = _tree(local.store.artifact_dir(l.info.run_id))
        served = server.artifacts / r.info.experiment_id / r.info.run_id / "artifacts"
        assert set(_tree(served)) == set(want)  # on the server's disk, uploaded over HTTP
        got = store.artifact_dir(r.info.run_id)  # downloaded back
        assert _tree(got) == _tree(served)
        assert set(r.data.metrics) == set(l.data.metrics)
    art = store.artifact_dir(remote.run_id)
    if name == "ppo":
        assert {"ppo.h5", "rollout.h5", "filmstrip.png", "config.yaml", "search.h5"} <= set(_tree(art))
        from toolkit.rl.checkpoint import load_policy

        assert load_policy(art / "ppo.h5") is not None  # the checkpoint, downloaded, loads
        assert h5.read(art / "rollout.h5")["root"].shape[1] == 7
        assert (art / "filmstrip.png").read_bytes()[:4] == b"\x89PNG"
    else:
        mine, theirs = h5.read(art / "search.h5"), h5.read(local.store.artifact_dir(local.run_id) / "search.h5")
        assert (mine["history"]["x"] == theirs["history"]["x"]).all()
        assert [e.metrics for e in remote.evaluations] == [e.metrics for e in local.evaluations]
    assert remote.metrics.keys() == local.metrics.keys()


def test_jt_show_reads_the_server(runs, server, tmp_path, monkeypatch):
    monkeypatch.setenv("JT_WORK_DIR", str(tmp_path / "cache"))  # where the downloads go
    remote = runs["bds"][0]
    out = run_jt("show", remote.run_id, f"store={server.uri}", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert f"run {remote.run_id}  [FINISHED]" in out.stdout and "search.h5  (" in out.stdout
    assert "task:" in out.stdout and "child runs: 10" in out.stdout
    missing = run_jt("show", "0123456789abcdef", f"store={server.uri}", cwd=tmp_path)
    assert missing.returncode == 2 and "no run '0123456789abcdef'" in missing.stderr


def test_jt_ui_prints_the_server_url(server, tmp_path):
    t0 = time.monotonic()
    out = run_jt("ui", f"store={server.uri}/", cwd=tmp_path, timeout=60)
    assert out.returncode == 0 and f"MLflow UI: {server.uri}/#/experiments?workflowType=machine_learning  (served by the tracking server)" \
        in out.stdout
    assert time.monotonic() - t0 < 30  # it starts nothing


def test_unreachable_server_is_one_line(tmp_path):
    out = run_jt("show", "abc", f"store=http://127.0.0.1:{free_port()}", cwd=tmp_path, timeout=60)
    assert out.returncode == 2 and out.stderr.count("\n") == 1 and "no MLflow server answers" in out.stderr


def test_interrupted_run_resumes_through_the_server(server, example_plugin_dir, tmp_path, monkeypatch):
    """Ctrl-C a search on a server store, then ``jt run resume=ID store=http://...`` on the same
    driver (its work cache holds the config and the search history)."""
    import signal
    import subprocess
    import sys

    from tests.conftest import jt_env

    monkeypatch.setenv("JT_WORK_DIR", str(tmp_path / "cache"))
    args = ["task=quadratic", "task.sleep=2.0", "search=random", "search.budget=5", "executor.workers=1",
            f"store={server.uri}", "seed=1"]
    # Ctrl-C as in a terminal, also where the suite runs as a background job (SIGINT ignored there)
    proc = subprocess.Popen([sys.executable, "-m", "toolkit.cli", "run", *args], env=jt_env(example_plugin_dir),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        err, deadline = "", time.monotonic() + 120
        while "[2/5]" not in err and time.monotonic() < deadline:  # two evaluations done
            line = proc.stderr.readline()
            if not line and proc.poll() is not None:
                break
            err += line
        proc.send_signal(signal.SIGINT)
        err += proc.communicate(timeout=60)[1]
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    run_id = err.split("jt: run ", 1)[1].split()[0]
    assert f"jt run resume={run_id} store={server.uri}" in err
    store = open_store(server.uri)
    tags = store.get_run(run_id).data.tags
    assert tags[HEARTBEAT_TAG] == "stopped" and f"pid {proc.pid} on " in tags[OWNER_TAG]
    # another machine's driver that beat a moment ago owns it: refused in one line, nothing changed
    store.set_tags(run_id, {OWNER_TAG: "pid 4242 on elsewhere (since 2026-12-02T03:00:00)",
                            HEARTBEAT_TAG: f"{time.time():.0f}"})
    refused = run_jt("run", f"resume={run_id}", f"store={server.uri}", extra_path=example_plugin_dir, cwd=tmp_path)
    assert refused.returncode == 2 and refused.stderr.count("\n") == 1, refused.stderr
    assert f"run {run_id} is being run by pid 4242 on elsewhere" in refused.stderr
    assert "jt.resumed" not in store.get_run(run_id).data.tags
    store.set_tags(run_id, {HEARTBEAT_TAG: f"{time.time() - STALE_S - 5:.0f}"})  # that driver died: stale
    again = run_jt("run", f"resume={run_id}", f"store={server.uri}", extra_path=example_plugin_dir, cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    assert "resumed after" in again.stderr and f"run {run_id} FINISHED" in again.stdout
    hist = h5.read(store.artifact_dir(run_id) / "search_history.h5")  # downloaded from the server
    assert list(hist["index"]) == list(range(5))


def test_the_heartbeat_beats_and_stops(server, tmp_path, monkeypatch):
    """The owner's tags on a real server: set at start, renewed every period, ``stopped`` at the
    end; ``check_not_owned`` refuses only another host's fresh beat."""
    monkeypatch.setenv("JT_WORK_DIR", str(tmp_path / "cache"))
    store = open_store(server.uri)
    rid = store.start_run("heartbeat", run_name="hb")
    hb = Heartbeat(store, rid, period_s=0.4).start()
    try:
        first = float(store.get_run(rid).data.tags[HEARTBEAT_TAG])
        time.sleep(1.8)
        assert float(store.get_run(rid).data.tags[HEARTBEAT_TAG]) >= first + 1
        check_not_owned(store, store.get_run(rid))  # this host's own: the lock decides
    finally:
        hb.stop()
    assert store.get_run(rid).data.tags[HEARTBEAT_TAG] == "stopped"
    store.set_tags(rid, {OWNER_TAG: "pid 7 on elsewhere (since now)", HEARTBEAT_TAG: f"{time.time():.0f}"})
    with pytest.raises(JtError, match="is being run by pid 7 on elsewhere"):
        check_not_owned(store, store.get_run(rid))
    check_not_owned(store, store.get_run(rid), now=time.time() + STALE_S + 1)  # stale: a dead owner
    store.set_tags(rid, {HEARTBEAT_TAG: "stopped"})
    check_not_owned(store, store.get_run(rid))
    check_not_owned(Store(tmp_path / "local"), store.get_run(rid))  # a local store: the lock alone


def test_of_two_resumes_at_once_only_the_last_to_write_goes_on(server, tmp_path, monkeypatch):
    """Both write ``jt.owner``; read back after the confirm delay, only the one named there stays."""
    monkeypatch.setenv("JT_WORK_DIR", str(tmp_path / "cache"))
    store = open_store(server.uri)
    rid = store.start_run("heartbeat", run_name="race")
    first = Heartbeat(store, rid, period_s=60).start()
    second = Heartbeat(store, rid, period_s=60).start()
    second.owner = first.owner + " [second]"  # two processes of this test: tell them apart
    store.set_tags(rid, {OWNER_TAG: second.owner})
    try:
        with pytest.raises(JtError, match=f"run {rid} was taken a moment ago by .*\\[second\\]"):
            first.confirm(wait_s=0.1)
        second.confirm(wait_s=0.1)
    finally:
        first.stop()
        second.stop()
