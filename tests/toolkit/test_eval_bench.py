"""``jt bench evaluation``: one ``jt run`` in a fresh process, its wall time broken into phases
from the ``wall_*_s`` metrics its evaluation recorded in a real store."""

from __future__ import annotations

import json

import pytest

from tests.conftest import one_line_error, run_jt


def test_a_runs_wall_time_is_broken_into_its_phases(tmp_path):
    out = tmp_path / "b.json"
    p = run_jt("bench", "evaluation", "task=runup", "experiment=smoke", "action=pvae", "action.prior=auto",
               "--store", str(tmp_path / "s"), "--json", str(out), "--quiet", timeout=600)
    assert p.returncode == 0, p.stderr[-800:]
    res = json.loads(out.read_text())
    ph = res["phases"]
    assert res["evaluations"] == 1 and res["samples"] == 128
    assert {"startup", "collect", "update", "hooks", "checkpoint", "final rollout", "pictures", "measure",
            "outside evaluations"} <= set(ph)
    assert ph["collect"] > 0 and ph["update"] > 0 and ph["final rollout"] > 0
    assert ph["prior"] > 0  # the store had no P-VAE prior: the run trained one first
    assert sum(ph.values()) == pytest.approx(res["wall_s"], rel=1e-6)  # every second is in one phase
    assert 0 < res["eval_s"] < res["wall_s"]
    text = p.stdout
    assert "jt run task=runup experiment=smoke action=pvae action.prior=auto  (run " in text and "total (wall)" in text
    assert "samples/s: " in text and "while collecting" in text
    # the evaluation's own metrics, as the store has them
    from toolkit.store.opening import open_store

    client = open_store(tmp_path / "s", must_exist=True).client
    m = client.get_run(res["run_id"]).data.metrics
    parts = sum(m[f"wall_{k}_s"] for k in ("startup", "collect", "update", "hooks", "checkpoint"))
    assert parts <= m["train_wall_s"] + 1e-6 and m["train_wall_s"] < m["eval_seconds"]


def test_bad_input_is_one_line(tmp_path):
    err = one_line_error(run_jt("bench", "evaluation"))
    assert "needs jt run's overrides, e.g.: jt bench evaluation task=TASK experiment=laptop" in err
    err = one_line_error(run_jt("bench", "evaluation", "task=runup", "store=/tmp/x"))
    assert "give the store with --store, not store=" in err
    err = one_line_error(run_jt("bench", "evaluation", "task=nosuch"))
    assert "nosuch" in err


def test_a_run_that_fails_is_one_line_with_its_reason(tmp_path):
    (tmp_path / "a_file").write_text("not a store")
    err = one_line_error(run_jt("bench", "evaluation", "task=runup", "experiment=smoke", "--quiet",
                                "--store", str(tmp_path / "a_file")))
    assert err.startswith("jt: jt bench evaluation: jt run failed (exit 2): store=") and "is a file, not a folder" in err
