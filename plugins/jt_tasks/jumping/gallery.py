"""The strategies a Stage-1 search found: a table and a gallery (``000`` §7.1, Fig. 7, Table 3).

BDS counts a strategy as new when its feature (the root's up-angle over the bar, ``000`` §6.1.4)
is at least ``distinct_threshold`` from every strategy found before it (``000`` §7.1.1: "6
distinct strategies in the first ten samples"). ``strategies`` applies that rule to the
evaluations in the order they ran; ``table`` gives one row per strategy; ``write`` puts in a
folder one labelled picture of each strategy's pose as its CoM crosses the bar plane
(``peak.png`` of its evaluation), that evaluation's GIF, ``gallery.png`` (all of them side by
side) and ``strategies.json``.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path
from typing import Any, Callable, Optional, Sequence

import numpy as np

PEAK = "peak.png"
"""An evaluation's picture of its pose as the CoM crosses the bar plane."""
COLUMNS = ("strategy", "eval", "feature_rad", "bar_m", "success", "takeoff", "run_id")


def strategies(items: Sequence[dict], threshold: float,
               distance: Optional[Callable[[Any, Any], Any]] = None) -> list[dict]:
    """Group evaluations into strategies, in the order they ran.

    Args:
        items: one dict per evaluation: ``index``, ``features`` ``(n_features,)`` (empty when it
            failed), ``metrics``, ``point`` (take-off features), ``run_id``, ``workdir``.
        threshold: features at least this far from every earlier strategy start a new one.
        distance: feature distance (default Euclidean).

    Returns:
        One dict per strategy: the first evaluation that found it (its keys, plus ``strategy``
        numbered from 1 and ``members``, the indices of the evaluations within ``threshold``).
    """
    dist = distance or (lambda a, b: float(np.linalg.norm(np.asarray(a, float) - np.asarray(b, float))))
    found: list[dict] = []
    for it in items:
        f = list(it.get("features") or ())
        if not f or not all(math.isfinite(float(x)) for x in f):
            continue
        near = [s for s in found if float(dist(f, s["features"])) < threshold]
        if near:
            near[0]["members"].append(it["index"])
            continue
        found.append({**it, "features": f, "strategy": len(found) + 1, "members": [it["index"]]})
    return found


def table(found: Sequence[dict]) -> tuple[list[str], list[list[Any]]]:
    """``(columns, rows)``: strategy, evaluation index, feature (rad), bar height reached (m), the
    deterministic jump's success, take-off features, evaluation run id."""
    rows = []
    for s in found:
        m = s.get("metrics", {})
        takeoff = ", ".join(f"{k} {float(v):+.2f}" for k, v in (s.get("point") or {}).items())
        rows.append([s["strategy"], s["index"], round(float(s["features"][0]), 3),
                     round(float(m.get("bar_height_reached", math.nan)), 3),
                     int(float(m.get("final_success", 0.0)) > 0.5), takeoff, s.get("run_id", "")])
    return list(COLUMNS), rows


def label(frame: np.ndarray, lines: Sequence[str]) -> np.ndarray:
    """``frame`` ``(h, w, 3)`` uint8 with ``lines`` of text on a white band below it."""
    from PIL import Image, ImageDraw

    img = Image.fromarray(np.asarray(frame, dtype=np.uint8)[..., :3])
    band = 14 * len(lines) + 6
    out = Image.new("RGB", (img.width, img.height + band), (255, 255, 255))
    out.paste(img, (0, 0))
    draw = ImageDraw.Draw(out)
    for i, text in enumerate(lines):
        draw.text((4, img.height + 3 + 14 * i), text, fill=(0, 0, 0))
    return np.asarray(out)


def caption(s: dict) -> list[str]:
    """The text under a strategy's picture."""
    m = s.get("metrics", {})
    pt = s.get("point") or {}
    return [f"strategy {s['strategy']} (eval {s['index']}): feature {float(s['features'][0]):.2f} rad",
            f"bar {float(m.get('bar_height_reached', math.nan)):.2f} m, "
            f"{'cleared' if float(m.get('final_success', 0.0)) > 0.5 else 'not cleared'}",
            " ".join(f"{k}={float(v):.2f}" for k, v in pt.items())]


def write(found: Sequence[dict], folder: Path) -> list[Path]:
    """Write the gallery of ``found`` (``strategies``' output) into ``folder``; the files written."""
    import imageio.v3 as iio

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    tiles = []
    for s in found:
        wd = Path(s.get("workdir") or "")
        n = s["strategy"]
        if (wd / PEAK).is_file():
            tile = label(iio.imread(wd / PEAK), caption(s))
            out = folder / f"strategy_{n}_peak.png"
            iio.imwrite(out, tile)
            written.append(out)
            tiles.append(tile)
        if (wd / "motion.gif").is_file():
            out = folder / f"strategy_{n}.gif"
            shutil.copyfile(wd / "motion.gif", out)
            written.append(out)
    if tiles:
        h = max(t.shape[0] for t in tiles)
        padded = [np.pad(t, ((0, h - t.shape[0]), (0, 4), (0, 0)), constant_values=255) for t in tiles]
        out = folder / "gallery.png"
        iio.imwrite(out, np.concatenate(padded, axis=1))
        written.append(out)
    cols, rows = table(found)
    out = folder / "strategies.json"
    out.write_text(json.dumps({"columns": cols, "rows": rows}, indent=1))
    written.append(out)
    return written
