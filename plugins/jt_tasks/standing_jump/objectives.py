"""Objectives of ``004``: jump height vs effort, the penalty terms of eqs 1–3, eq 5, fronts.

RMOO (``004`` §4.2–4.3) optimises two objectives at once: the jump height and the effort
``log(w_JE e_JE + w_SE e_SE)`` (§4.3.2; eqs 4 and 6). In jt every objective is minimised, so the
task returns ``(-height, log effort)``. A failed jump (a fall, a landing outside the box) gets the
failure penalty ``f_p`` added to both (the landing term ``C_L`` of eq 3, "a constant and large
failure penalty"), which keeps it behind every successful sample and outside the hypervolume box.

BSOO (§4.1) instead minimises ``f_SO = f_H + log(w_JE e_JE + w_SE e_SE)`` (eq 5) per height bin,
with ``f_H = C_H + C_L`` (eqs 1–3); ``f_so`` computes it from the two objectives, so a binned
searcher can rebuild it from what the task returns.
"""

from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np


def effort(e_je: float, e_se: float, w_je: float = 1.0, w_se: float = 5000.0) -> float:
    """``log(w_JE e_JE + w_SE e_SE)`` (``004`` §4.3.2; ``w_SE / w_JE = 5000``)."""
    return math.log(w_je * e_je + w_se * e_se)


def c_h(height: float, target: float, tolerance: float, w_p: float = 5000.0) -> float:
    """Head-height constraint, ``004`` eq 2: ``w_p (h_p - h_o)^2`` outside the bracket, else 0."""
    d = height - target
    return w_p * d * d if abs(d) > tolerance else 0.0


def c_l(landing: float, target: float, tolerance: float, f_p: float = 1e5) -> float:
    """Landing constraint, ``004`` eq 3: ``f_p`` when ``|l_p - l_o| > l_r``, else 0."""
    return f_p if not abs(landing - target) <= tolerance else 0.0


def f_so(objectives: Sequence[float], height_target: float, height_tolerance: float,
         w_p: float = 5000.0, f_p: float = 1e5) -> float:
    """BSOO's single objective ``f_H + log(...)`` (``004`` eqs 1, 5) from the task's objectives.

    Args:
        objectives: ``(-height, log effort)`` as the task returns them (failures carry ``+f_p``).
        height_target: the bin's target head height ``h_o`` (m).
        height_tolerance: the bin's bracket ``h_r`` (m).
        w_p: height penalty weight.
        f_p: failure penalty.
    """
    neg_h, eff = float(objectives[0]), float(objectives[1])
    failed = neg_h >= 0.5 * f_p
    if failed:
        neg_h -= f_p
        eff -= f_p
    return c_h(-neg_h, height_target, height_tolerance, w_p) + (f_p if failed else 0.0) + eff


def jump_objectives(height: float, e_je: float, e_se: float, failed: bool, w_je: float = 1.0,
                    w_se: float = 5000.0, f_p: float = 1e5) -> list[float]:
    """The task's two minimised objectives ``(-height, log effort)``, ``+f_p`` each on failure."""
    h = height if math.isfinite(height) else 0.0
    eff = effort(e_je, e_se, w_je, w_se) if math.isfinite(e_je) and math.isfinite(e_se) else f_p
    pen = f_p if failed else 0.0
    return [-h + pen, eff + pen]


def effort_bound(torque_limits: dict[str, float], weights: dict[str, float], max_time: float, mass: float,
                 max_assist: float, max_assist_time: float, w_je: float = 1.0, w_se: float = 5000.0) -> float:
    """An effort objective no evaluation can exceed: every joint at its torque limit all episode,
    and the largest assist applied at full strength for its longest duration."""
    e_je = sum(weights[j] * torque_limits[j] ** 2 for j in weights) * max_time
    e_se = (mass * max_assist) ** 2 * max_assist_time
    return effort(e_je, e_se, w_je, w_se)


def non_dominated(F: np.ndarray, valid: Optional[np.ndarray] = None) -> np.ndarray:
    """Flag the non-dominated rows of ``F`` ``(n, m)`` (all minimised, ``004`` eqs 8–9).

    Args:
        F: objective vectors.
        valid: rows allowed on the front ``(n,)`` (default all).

    Returns:
        Boolean mask ``(n,)``; duplicates of a front point are all flagged.
    """
    F = np.asarray(F, dtype=float)
    n = len(F)
    ok = np.ones(n, bool) if valid is None else np.asarray(valid, bool).copy()
    ok &= np.all(np.isfinite(F), axis=1) if n else ok
    mask = np.zeros(n, bool)
    idx = np.flatnonzero(ok)
    for i in idx:
        others = F[idx]
        dominated = np.any(np.all(others <= F[i], axis=1) & np.any(others < F[i], axis=1))
        mask[i] = not dominated
    return mask


def hypervolume(F: np.ndarray, reference: Sequence[float], valid: Optional[np.ndarray] = None) -> float:
    """Hypervolume of the rows of ``F`` ``(n, m)`` dominating ``reference`` (``004`` eq 13)."""
    import moocore

    F = np.asarray(F, dtype=float)
    ref = np.asarray(reference, dtype=float)
    if F.size == 0:
        return 0.0
    keep = np.all(np.isfinite(F), axis=1) & np.all(F < ref, axis=1)
    if valid is not None:
        keep &= np.asarray(valid, bool)
    if not np.any(keep):
        return 0.0
    return float(moocore.hypervolume(F[keep], ref=ref))
