"""A whole Stage-1 search at smoke size: real features reach BDS, the strategies are counted, and
the outer run carries the gallery and the strategy table (000 §7.1.1, Fig. 7)."""

from __future__ import annotations

import json
import math

import pytest


@pytest.fixture(scope="module")
def search(tmp_path_factory):
    from toolkit.config import compose
    from toolkit.execution.runner import run

    root = tmp_path_factory.mktemp("store")
    return run(compose(["task=highjump", "search=bds", "experiment=smoke", f"store={root}"]))


def test_smoke_search_gives_bds_real_features(search):
    feats = [ev.features[0] for ev in search.evaluations if len(ev.features)]
    assert len(feats) >= 1 and all(0.0 <= f <= math.pi for f in feats)
    assert search.metrics["n_with_feature"] == len(feats)
    assert 1 <= search.metrics["n_strategies"] <= len(feats)


def test_outer_run_has_gallery_and_table(search):
    art = search.store.artifact_dir(search.run_id)
    n = int(search.metrics["n_strategies"])
    assert (art / "gallery" / "gallery.png").is_file()
    assert all((art / "gallery" / f"strategy_{k}_peak.png").is_file() for k in range(1, n + 1))
    table = json.loads((art / "gallery" / "strategies.json").read_text())
    assert len(table["rows"]) == n
    run_ids = {ev.run_id for ev in search.evaluations}
    row = dict(zip(table["columns"], table["rows"][0]))
    assert row["run_id"] in run_ids and row["run_id"]  # the evaluation that found it


def test_jt_show_prints_the_strategies(search):
    from toolkit.execution.show import show

    out = show(search.run_id, str(search.store.root))
    table = out[out.index("summary table:"):]
    assert "feature_rad" in table and "bar_m" in table
