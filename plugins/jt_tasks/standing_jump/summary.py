"""Run-level results of the standing-jump task: the front table (``004`` Tables 2–3), the Fig. 8
analogue and filmstrips of the key jumps (``004`` Fig. 9).

``front.h5`` holds one row per evaluated sample, in evaluation order, with the columns of Tables
2–3 (internal energy, take-off gravity, force application time) plus the height and a
non-dominated flag, and a ``front`` group with the non-dominated successful samples sorted by
height (the tables' rows).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from toolkit.interfaces.task import Evaluation

COLUMNS = ("internal_energy", "takeoff_gravity", "force_application_time", "height")
"""Table 2–3 columns (the paper's 'Internal Energy Joint Metric', 'Super-natural take-off gravity',
'Super-natural force application time'), plus the height the tables are sorted by."""


def _column(evs: Sequence[Evaluation], key: str) -> np.ndarray:
    return np.array([float(e.metrics.get(key, math.nan)) for e in evs], dtype=float)


def sample_table(evs: Sequence[Evaluation], reference: Sequence[float]) -> dict[str, np.ndarray]:
    """Columns over all samples, the non-dominated flag and the objectives."""
    from jt_tasks.standing_jump.objectives import non_dominated

    n = len(evs)
    F = np.full((n, 2), np.nan)
    for i, e in enumerate(evs):
        if len(e.objectives) == 2:
            F[i] = np.asarray(e.objectives, dtype=float)
    failed = np.array([bool(e.failed) for e in evs], dtype=bool)
    cols = {k: _column(evs, k) for k in COLUMNS + ("effort", "external_energy", "landing_x", "natural")}
    cols["natural"] = cols["natural"] > 0.5
    cols["failed"] = failed
    cols["objectives"] = F
    cols["non_dominated"] = non_dominated(F, valid=~failed & np.all(np.isfinite(F), axis=1)) if n else np.zeros(0, bool)
    cols["in_reference_box"] = np.all(F < np.asarray(reference, float), axis=1) if n else np.zeros(0, bool)
    return cols


def hypervolume_curve(F: np.ndarray, reference: Sequence[float], ok: np.ndarray) -> np.ndarray:
    """Hypervolume of the successful samples among the first ``k`` evaluations, ``k = 1..n`` → ``(n,)``.

    ``F`` ``(n, 2)`` objectives in evaluation order, ``ok`` ``(n,)`` success flags. Only the
    current front matters for the next value, so each step adds one point to a small set.
    """
    from jt_tasks.standing_jump.objectives import hypervolume, non_dominated

    out = np.zeros(len(F))
    front = np.zeros((0, F.shape[1] if F.ndim == 2 else 2))
    for i in range(len(F)):
        if ok[i] and np.all(np.isfinite(F[i])):
            front = np.vstack([front, F[i][None]])
            front = front[non_dominated(front, valid=np.ones(len(front), bool))]
        out[i] = hypervolume(front, reference, valid=np.ones(len(front), bool)) if len(front) else 0.0
    return out


def summarize(task: Any, evaluations: Sequence[Evaluation], workdir: Path) -> dict[str, float]:
    """Write ``front.h5``, ``front.png`` and filmstrips to ``workdir``; return run metrics."""
    from jt_tasks.standing_jump import params as P
    from jt_tasks.standing_jump.objectives import hypervolume
    from jt_tasks.standing_jump.render import animation, filmstrip, front_plot
    from toolkit.store import h5

    evs = list(evaluations)
    ref = task.reference_point()
    t = sample_table(evs, ref)
    names = P.param_names()
    X = np.array([[float(e.point.get(k, math.nan)) for k in names] for e in evs], dtype=float).reshape(-1, len(names))
    ok = ~t["failed"]
    front_idx = np.flatnonzero(t["non_dominated"])
    front_idx = front_idx[np.argsort(t["height"][front_idx])]
    table = {k: t[k] for k in COLUMNS}
    curve = hypervolume_curve(t["objectives"], ref, ok)
    h5.write(workdir / "front.h5", {
        "samples": {**table, "effort": t["effort"], "external_energy": t["external_energy"],
                    "landing_x": t["landing_x"], "natural": t["natural"], "failed": t["failed"],
                    "non_dominated": t["non_dominated"], "objectives": t["objectives"], "x": X},
        "front": {**{k: v[front_idx] for k, v in table.items()}, "index": front_idx,
                  "effort": t["effort"][front_idx], "natural": t["natural"][front_idx], "x": X[front_idx]},
        "hypervolume_curve": curve,
        "param_names": np.array(names),
        "objective_names": np.array(["neg_height", "effort"]),
        "reference_point": np.asarray(ref, float),
    }, attrs={"format": "jt.standing_jump.front/1", "columns": ",".join(COLUMNS)})

    natural = ok & t["natural"]
    supern = ok & ~t["natural"]
    nat_h = t["height"][natural]
    out = {
        "hypervolume": hypervolume(t["objectives"], ref, valid=ok),
        "n_front": float(front_idx.size),
        "n_front_natural": float(np.sum(t["natural"][front_idx])),
        "n_success": float(np.sum(ok)),
        "max_natural_height": float(nat_h.max()) if nat_h.size else math.nan,
        "max_height": float(t["height"][ok].max()) if np.any(ok) else math.nan,
        "min_effort": float(t["effort"][ok].min()) if np.any(ok) else math.nan,
    }
    out["hypervolume_curve"] = [(i + 1, float(v)) for i, v in enumerate(curve)]  # vs simulations (004 §5)
    if evs:
        front_plot(t["height"], t["effort"], t["non_dominated"], t["natural"], t["failed"], workdir / "front.png",
                   out["max_natural_height"])
    if task.params.filmstrips:
        picks = []
        if np.any(natural):
            i_nat = np.flatnonzero(natural)
            picks.append(("lowest_natural", int(i_nat[np.argmin(t["height"][i_nat])])))
            picks.append(("highest_natural", int(i_nat[np.argmax(t["height"][i_nat])])))
        if np.any(supern):
            i_sup = np.flatnonzero(supern)
            picks.append(("highest_supernatural", int(i_sup[np.argmax(t["height"][i_sup])])))
        settings = task.settings()
        for label, i in picks:
            if evs[i].point:
                filmstrip(evs[i].point, workdir / f"filmstrip_{label}.png", f"{label.replace('_', ' ')} (sample {i})",
                          settings, task.params.filmstrip_width, task.params.filmstrip_height)
                animation(evs[i].point, workdir / f"jump_{label}.gif", settings,  # the same jump, moving
                          task.params.filmstrip_width, task.params.filmstrip_height)
    return out
