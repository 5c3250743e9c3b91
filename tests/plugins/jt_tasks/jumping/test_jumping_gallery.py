"""The strategy table and gallery of a Stage-1 search (jt_tasks.jumping.gallery)."""

from __future__ import annotations

import json
import math

import numpy as np

from jt_tasks.jumping import gallery
from jt_tasks.jumping.features import angle_distance


def _item(i, feature, workdir="", bar=0.55, success=1.0):
    return {"index": i, "features": [] if feature is None else [feature], "point": {"alpha": 0.1 * i},
            "metrics": {"bar_height_reached": bar, "final_success": success}, "run_id": f"r{i}",
            "workdir": str(workdir)}


def test_strategies_follow_the_threshold_in_the_order_they_ran():
    items = [_item(0, 1.0), _item(1, None), _item(2, 1.3), _item(3, 1.6), _item(4, 0.2), _item(5, math.nan)]
    found = gallery.strategies(items, 0.5, angle_distance)
    # 1.3 is within 0.5 of 1.0; 1.6 is 0.6 from 1.0 (a new one); 0.2 is new; failed and NaN skipped
    assert [s["index"] for s in found] == [0, 3, 4]
    assert [s["strategy"] for s in found] == [1, 2, 3]
    assert found[0]["members"] == [0, 2]
    assert len(gallery.strategies(items, 2.0, angle_distance)) == 1


def test_table_has_one_row_per_strategy():
    found = gallery.strategies([_item(0, 1.0), _item(1, 2.0, success=0.0)], 0.5, angle_distance)
    cols, rows = gallery.table(found)
    assert cols[0] == "strategy" and len(rows) == 2
    assert rows[1][cols.index("feature_rad")] == 2.0
    assert rows[1][cols.index("success")] == 0 and rows[0][cols.index("success")] == 1
    assert rows[1][cols.index("run_id")] == "r1"


def test_write_labels_each_strategy_and_joins_them(tmp_path):
    import imageio.v3 as iio

    dirs = []
    for i in range(2):
        d = tmp_path / f"eval_{i:04d}"
        d.mkdir()
        iio.imwrite(d / gallery.PEAK, np.full((60, 80, 3), 40 * (i + 1), np.uint8))
        iio.imwrite(d / "motion.gif", np.zeros((3, 60, 80, 3), np.uint8), duration=100)
        dirs.append(d)
    found = gallery.strategies([_item(0, 0.5, dirs[0]), _item(1, 2.5, dirs[1])], 0.5, angle_distance)
    out = tmp_path / "gallery"
    names = sorted(p.name for p in gallery.write(found, out))
    assert names == ["gallery.png", "strategies.json", "strategy_1.gif", "strategy_1_peak.png",
                     "strategy_2.gif", "strategy_2_peak.png"]
    tile = iio.imread(out / "strategy_1_peak.png")
    assert tile.shape[0] > 60 and tile.shape[1] == 80  # the caption band is below the picture
    assert (tile[-20:] < 255).any()  # text was drawn on the white band
    assert iio.imread(out / "gallery.png").shape[1] == 2 * (80 + 4)
    table = json.loads((out / "strategies.json").read_text())
    assert [r[0] for r in table["rows"]] == [1, 2]
