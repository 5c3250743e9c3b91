"""The robustness evaluation of ``003`` §6.3 / Table 1 and the feature-curve plot.

Table 1: "we evaluate the robustness of the trained policy by starting from 100 different terrain
locations and tracking the success of the agent" (§6.3), per region (flat, easy, medium, hard) and
overall. Here: for each region of ``task.eval_regions``, ``task.eval_locations`` passive rag-doll
drops at seeded locations of the region (``task.eval_seed``, never the training states' seed), one
deterministic get-up from each (the curve picked by the 30° rule of §5.2, seeded), and per region:

* ``success_<region>``: share of successes (``GetupEnv``: not terminated early and standing for
  the last ``success_window`` s, §6.3 "remains standing after getting up"); ``success_overall``
  over all the evaluated episodes (Table 1's "Overall");
* ``rise_<region>``: share that reached the standing height at some point (``got_up``);
* ``time_to_rise_<region>``: mean s from the start to the first standing height, over those that rose;
* ``return_rate_<region>``: mean task return rate (Σ r_task / the episode's steps, §6.4);
* ``early_<region>``: share terminated early (§5.3).

``table1.h5`` holds one row per episode (region, location, style, curve, each column above).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np

from jt_tasks.getup.terrain import REGIONS

COLUMNS = ("success", "got_up", "time_to_rise", "task_return_rate", "early")  #: per-episode values


def evaluate_regions(task: Any, spec: Any, model: Any) -> dict[str, dict[str, np.ndarray]]:
    """One deterministic get-up per evaluation drop of each region: ``{region: {column: (n,)}}``
    plus ``x``, ``z``, ``style`` (0 prone, 1 supine) and ``curve`` per episode."""
    from toolkit.policy.episodes import opened_env, rollout

    p = task.params
    out: dict[str, dict[str, np.ndarray]] = {}
    for name in p.eval_regions:
        region = REGIONS.index(name)
        states = task.fallen(spec.sim, [region], p.eval_locations, p.eval_seed)
        rows = []
        with opened_env(task.env_class, dataclasses.replace(spec, fallen=states), seed=0) as env:
            env.terrain_level = region
            for i, st in enumerate(states):
                info = rollout(env, model, options={"kind": "fallen", "fallen": i}).info
                rows.append({"success": info.get("success", 0.0), "got_up": info.get("got_up", 0.0),
                             "time_to_rise": info.get("time_to_rise", math.nan),
                             "task_return_rate": info.get("task_return_rate", 0.0),
                             "early": float(info.get("reason", "") not in ("time limit",)),
                             "x": st["xz"][0], "z": st["xz"][1], "style": float(st["style"] == "supine"),
                             "curve": info.get("curve", math.nan)})
        out[name] = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]} if rows else {}
    return out


def table_metrics(table: dict[str, dict[str, np.ndarray]]) -> dict[str, float]:
    """Table 1's figures from ``evaluate_regions``: per region and ``success_overall``."""
    out: dict[str, float] = {}
    for name, cols in table.items():
        if not cols:
            continue
        out[f"success_{name}"] = float(np.mean(cols["success"]))
        out[f"rise_{name}"] = float(np.mean(cols["got_up"]))
        rose = cols["time_to_rise"][np.isfinite(cols["time_to_rise"])]
        if len(rose):
            out[f"time_to_rise_{name}"] = float(np.mean(rose))
        out[f"return_rate_{name}"] = float(np.mean(cols["task_return_rate"]))
        out[f"early_{name}"] = float(np.mean(cols["early"]))
    every = [cols["success"] for cols in table.values() if cols]
    if every:
        out["success_overall"] = float(np.mean(np.concatenate(every)))
    return out


def write_table(path: Path, table: dict[str, dict[str, np.ndarray]], metrics: dict[str, float]) -> None:
    """``table1.h5``: a group per region with one row per episode; the table's figures as attributes."""
    from toolkit.store import h5

    data = {name: cols for name, cols in table.items() if cols}
    attrs = {k: v for k, v in metrics.items() if k.split("_")[0] in ("success", "rise", "time", "return", "early")}
    attrs["regions"] = ",".join(data)
    h5.write(path, data, attrs)


def plot_curves(path: Path, time: np.ndarray, features: np.ndarray, targets: np.ndarray, title: str = "") -> None:
    """``curves.png``: the features achieved (solid) against the curve's targets (dashed) over the
    rollout: h (m), θx and θz (deg)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(10, 2.8))
    labels = ("h (m)", "θx (deg)", "θz (deg)")
    for k, ax in enumerate(axes):
        scale = 1.0 if k == 0 else 180.0 / math.pi
        ax.plot(time, features[:, k] * scale, label="achieved")
        ax.plot(time, targets[:, k] * scale, "--", label="target")
        ax.set_xlabel("t (s)")
        ax.set_ylabel(labels[k])
    axes[0].legend(fontsize=7)
    if title:
        fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def replay_reference(env: Any, curve: str) -> dict[str, np.ndarray]:
    """The reference clip of ``curve`` replayed kinematically through the env's reward (issue check:
    the early termination must not fire on the reference itself): at every control step of ``[0, T]``
    the clip's pose (lifted onto the ground) is set, and the reward terms are read as in a step.

    Returns:
        ``time`` ``(n,)``, ``r_task`` ``(n,)``, one ``(n,)`` array per reward term, ``head_height``
        ``(n,)`` (lowest point of the head link above the ground, m).
    """
    import math as _m

    from jt_tasks.getup.curves import load_getup_clip
    from jt_tasks.getup.ground import lift_to_ground
    from jt_tasks.takeoff.state import reference_state

    env.reset(seed=0, options={"kind": "clip", "curve": curve})
    c = env.curve
    if not c.clip:
        raise ValueError(f"curve {curve!r} has no reference clip")
    clip = load_getup_clip(c.clip, c.mirrored)
    n = int(_m.floor(c.duration * env.control_hz)) + 1
    rows: list[dict[str, float]] = []
    for k in range(n):
        t = min(max(k / env.control_hz, 1.0 / 120.0), float(clip.times[-1]) - 1.0 / 120.0)
        p, r, j, v, w, jv = reference_state(clip, t)
        links = env.sim.link_states() if k else None
        env.sim.reset(lift_to_ground(np.concatenate([p, r, j])), np.concatenate([v, w, jv]))
        env.t_offset = k / env.control_hz - float(env.sim.time)  # the curve's clock at this frame
        env.state_changed(links)
        rec = env.record_now()
        values = {name: float(term(rec)) for name, term in env.terms.items()}
        rows.append({"time": k / env.control_hz,
                     "r_task": float(np.prod([x for name, x in values.items() if name not in env.natural])),
                     **values, "head_height": env._head_height()})
    return {key: np.array([row[key] for row in rows]) for key in rows[0]}


def longest_run(mask: np.ndarray) -> int:
    """Length of the longest run of True in ``mask``."""
    best = cur = 0
    for m in np.asarray(mask, bool):
        cur = cur + 1 if m else 0
        best = max(best, cur)
    return best

