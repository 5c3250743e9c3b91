"""jt ui opens MLflow 3 where jt's results are: the "Model training" view, each task's runs page in a
saved view of its key metrics, jt's experiments tagged as model development (when jt creates them,
and an existing store's when jt ui opens it), the page's defaults (Model training, the assistant
closed) and no telemetry. Real MLflow stores in temp dirs; the server is not started here
(test_ui.py starts one; test_ui_browser.py looks at it in Chromium, -m slow)."""

import asyncio
import json
import sqlite3
import subprocess
import sys

from tests.conftest import jt_env
from toolkit.execution import describe
from toolkit.store import ui, ui_app
from toolkit.store.tracking import Store

HIGHJUMP_KEYS = ("n_strategies", "n_with_feature", "strategy_angle", "bar_height_reached", "success_rate")


def _tags(root, eid):
    con = sqlite3.connect(root / "mlflow.db")
    try:
        return dict(con.execute("SELECT key, value FROM experiment_tags WHERE experiment_id = ?", (int(eid),)))
    finally:
        con.close()


def _old_store(root):
    """A store as an older jt left it: experiments with ``jt.task`` only, a run in each, and one
    experiment that is not jt's; ``(highjump id, spd_tracking id, other id)``."""
    store = Store(root)
    spd = store.describe_experiment("spd_tracking", "runs of spd_tracking", {"jt.task": "spd_tracking"})
    store.end_run(store.start_run("spd_tracking", run_name="older"))
    hj = store.describe_experiment("highjump", "runs of highjump", {"jt.task": "highjump"})
    store.end_run(store.start_run("highjump", run_name="newer"))
    other = store.experiment_id("other")
    return hj, spd, other


def test_urls_open_model_training_and_jts_view():
    assert ui.url(5077) == "http://127.0.0.1:5077/#/experiments?workflowType=machine_learning"
    assert ui.url(5077, "2") == "http://127.0.0.1:5077/#/experiments/2/runs?workflowType=machine_learning"
    assert ui.url(5077, "2", view=True) == ("http://127.0.0.1:5077/#/experiments/2/runs?workflowType=machine_learning"
                                            "&viewStateShareKey=jt")


def test_a_new_experiment_is_model_development_with_a_view_of_its_key_metrics(tmp_path):
    from toolkit import plugins

    store = Store(tmp_path / "s")
    eid = describe.ensure_experiment(store, "highjump", plugins.load("task", "highjump"))
    tags = store.client.get_experiment(eid).tags
    assert tags["mlflow.experimentKind"] == "custom_model_development" and tags["jt.task"] == "highjump"
    view = json.loads(tags["mlflow.sharedViewState.jt"])  # MLflow's saved-view envelope
    assert view["name"] == "jt: key metrics" and isinstance(view["createdAt"], int)
    state = json.loads(view["state"])
    keys = [f"metrics.`{k}`" for k in HIGHJUMP_KEYS]
    assert state["selectedColumns"][:5] == keys and "metrics.`best_success_rate`" in state["selectedColumns"]
    assert state["columnOrder"][:4] == ["attributes.`Run Name`", "runDateAndNestInfo", "duration", keys[0]]


def test_jt_ui_tags_an_existing_stores_experiments_once(tmp_path):
    root = tmp_path / "s"
    hj, spd, other = _old_store(root)
    assert ui.prepare(root) == [(hj, "highjump", True), (spd, "spd_tracking", True)]  # the newest run's first
    for eid in (hj, spd):
        assert _tags(root, eid)["mlflow.experimentKind"] == "custom_model_development"
    cols = json.loads(json.loads(_tags(root, spd)["mlflow.sharedViewState.jt"])["state"])["selectedColumns"]
    assert cols[0] == "metrics.`fps`"
    assert set(_tags(root, other)) <= {"mlflow.note.content"}  # not jt's: left alone
    before = {e: _tags(root, e) for e in (hj, spd, other)}
    assert ui.prepare(root) == [(hj, "highjump", True), (spd, "spd_tracking", True)]
    assert {e: _tags(root, e) for e in (hj, spd, other)} == before  # idempotent: nothing rewritten


def test_a_view_the_user_saved_over_stays_and_an_outdated_one_of_jts_is_renewed(tmp_path):
    root = tmp_path / "s"
    hj, spd, _ = _old_store(root)
    ui.prepare(root)
    con = sqlite3.connect(root / "mlflow.db")
    with con:
        mine = json.dumps({"name": "jt: key metrics", "createdAt": 1, "updatedAt": 2, "state": "{}"})  # as the UI saves
        con.execute("UPDATE experiment_tags SET value = ? WHERE key = ? AND experiment_id = ?",
                    (mine, ui.VIEW_TAG, int(hj)))
        stale = json.dumps({"name": "jt: key metrics", "createdAt": 5, "updatedAt": 5, "state": "{}",
                            "jt": ["metrics.`gone`"]})
        con.execute("UPDATE experiment_tags SET value = ? WHERE key = ? AND experiment_id = ?",
                    (stale, ui.VIEW_TAG, int(spd)))
    con.close()
    ui.prepare(root)
    assert _tags(root, hj)[ui.VIEW_TAG] == mine
    renewed = json.loads(_tags(root, spd)[ui.VIEW_TAG])
    assert renewed["createdAt"] == 5 and renewed["jt"][0] == "metrics.`fps`"


CLI = """
import sys
from toolkit.store import ui
ui.serve = lambda root, port: print("serving", port) or 0  # MLflow's server is test_ui.py's
ui.open_when_up = lambda target, port: print("opening", target)
from toolkit.cli import main
sys.argv = ["jt", "ui", *sys.argv[1:]]
main()
"""


def test_jt_ui_prints_each_tasks_runs_page_and_opens_the_newest(tmp_path):
    root = tmp_path / "s"
    hj, spd, _ = _old_store(root)
    out = subprocess.run([sys.executable, "-c", CLI, f"store={root}", "--port", "5099", "--open"], env=jt_env(),
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0] == f"MLflow UI for {root} (Ctrl-C to stop):"
    assert lines[1].split() == ["highjump", ui.url(5099, hj, view=True)]
    assert lines[2].split() == ["spd_tracking", ui.url(5099, spd, view=True)]
    assert lines[3].split() == ["all", "experiments", ui.url(5099)]
    assert f"opening {ui.url(5099, hj, view=True)}" in lines and "serving 5099" in lines
    assert _tags(root, hj)["mlflow.experimentKind"] == "custom_model_development"


def test_the_server_is_jts_app_without_telemetry(tmp_path):
    cmd, env = ui.command(tmp_path, 5001)
    assert "--app-name" in cmd, "jt's mlflow.app entry point is not installed: pip install -e . adds it"
    assert cmd[cmd.index("--app-name") + 1] == "jt-ui"
    assert env["MLFLOW_DISABLE_TELEMETRY"] == "true" and env["DO_NOT_TRACK"] == "true"


def _get(path, status=200, headers=(), body=b"<!doctype html><html><head><title>MLflow</title></head></html>"):
    """One GET through ``app`` wrapping a stand-in for MLflow's app; (response start, body, what it was asked)."""
    asked = {}

    async def inner(scope, receive, send):
        asked.update(scope)
        await send({"type": "http.response.start", "status": status, "headers": [
            (b"content-type", b"text/html; charset=utf-8"), (b"content-length", str(len(body)).encode()),
            (b"etag", b'"abc"'), *headers]})
        await send({"type": "http.response.body", "body": body[:10], "more_body": True})
        await send({"type": "http.response.body", "body": body[10:]})

    sent = []

    async def send(message):
        sent.append(message)

    async def receive():
        return {"type": "http.request"}

    scope = {"type": "http", "method": "GET", "path": path,
             "headers": [(b"accept-encoding", b"gzip"), (b"if-none-match", b'"abc"'), (b"host", b"x")]}
    asyncio.run(ui_app.DefaultsApp(lambda: inner)(scope, receive, send))
    return sent[0], b"".join(m.get("body", b"") for m in sent[1:]), asked


def test_the_page_sets_mlflows_defaults_before_mlflows_script():
    start, body, asked = _get("/")
    assert body.startswith(b"<!doctype html><html><head><script data-jt=\"defaults\">")
    assert b'"mlflow.workflowType_v1": "\\"machine_learning\\""' in body
    assert b"mlflow.assistant.fab.autoOpenedOnFirstLoad_v1" in body and b"getItem(k)===null" in body
    headers = dict(start["headers"])
    assert headers[b"content-length"] == str(len(body)).encode() and b"etag" not in headers
    assert [k for k, _ in asked["headers"]] == [b"host"]  # the whole page, uncompressed, every time
    _, js, _ = _get("/static-files/main.js", body=b"<head>not the page")
    assert js == b"<head>not the page"
    _, gz, _ = _get("/", headers=[(b"content-encoding", b"gzip")], body=b"<head>compressed")
    assert gz == b"<head>compressed"
    not_modified, empty, _ = _get("/", status=304, body=b"")
    assert not_modified["status"] == 304 and empty == b""
