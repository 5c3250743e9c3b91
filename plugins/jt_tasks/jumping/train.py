"""The jump's training hooks (``000`` Alg. 1 line 9): PPO with a curriculum up to ``z_freeze``.

``curriculum_hooks`` gives ``PolicyTask`` what an evaluation of a jump adds to the shared
training: the curriculum bound to PPO's ``extra`` (its state is checkpointed in ``ppo.h5``, so a
killed evaluation resumes), its per-iteration update (bar height / obstacle width, control rate,
``c_offset``, set on every environment), the stop at ``z_freeze`` (``000`` §6.1.4), the curves
``z`` and success rate per iteration, and Stage 2's mean ``r_novelty`` per iteration.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Optional

import numpy as np

from toolkit.policy.task import Hooks


def curriculum_hooks(spec: Any, cur: Any, total_samples: int, progress: Optional[Any],
                     warm_start: Any = None) -> Hooks:
    """PPO hooks of one jump evaluation.

    Args:
        spec: the ``EnvSpec`` (its ``control_hz`` becomes the curriculum's first rate).
        cur: the curriculum (``bind``, ``env_attrs``, ``on_iteration``, ``frozen``, ``z``).
        total_samples: the budget (for progress fractions).
        progress: ``progress(fraction, message)`` or None.
        warm_start: Stage 2's Stage-1 ``ppo.h5``, or None.
    """
    extra = cur.bind({})
    attrs0 = cur.env_attrs()
    spec = dataclasses.replace(spec, control_hz=float(attrs0.get("control_hz", spec.control_hz)))
    z_attr = next((k for k in attrs0 if k in ("bar_height", "obstacle_width")), "bar_height")
    z_hist: list[tuple[float, float, float]] = []  # (samples, z, success rate) per iteration

    def on_iteration(it: int, samples: int, stats: Any) -> dict[str, Any]:
        if not z_hist and extra.get("z_history") is not None:  # resumed: continue the saved curve
            z_hist.extend(tuple(float(x) for x in row) for row in np.asarray(extra["z_history"]).reshape(-1, 3))
        out = cur.on_iteration(it, samples, stats)
        eps = getattr(stats, "episodes", []) or []
        rate = float(np.mean([e.get("success", 0.0) for e in eps])) if eps else math.nan
        z_hist.append((float(samples), float(out.get(z_attr, math.nan)), rate))
        extra["z_history"] = np.asarray(z_hist, dtype=np.float64)
        nov = [float(e["r_novelty"]) for e in eps if "r_novelty" in e]
        if nov:  # Stage 2: mean r_novelty (000 eq 12) of the iteration's episodes
            prev = np.asarray(extra.get("novelty_history", np.zeros((0, 2))), dtype=np.float64).reshape(-1, 2)
            extra["novelty_history"] = np.vstack([prev, [[float(samples), float(np.mean(nov))]]])
        if progress is not None:
            from toolkit.execution.progress import figure

            progress(min(samples / max(total_samples, 1), 1.0), f"{z_attr} {figure(out.get(z_attr), '.3f')} m, "
                                                                 f"success {figure(rate, '.2f')}")
        return out

    return Hooks(on_iteration=on_iteration, extra=extra, should_stop=cur.frozen, warm_start=warm_start,
                 spec=spec, state={"cur": cur, "z_attr": z_attr, "z_hist": z_hist})


def after_training(hooks: Hooks, result: Any) -> None:
    """The curriculum and its curve as training left them (also after a resume)."""
    cur, state = hooks.state["cur"], hooks.state
    saved = result.extra.get("z_history")
    if saved is not None and len(np.asarray(saved)) >= len(state["z_hist"]):
        state["z_hist"][:] = [tuple(float(x) for x in row) for row in np.asarray(saved).reshape(-1, 3)]
    if result.extra.get(cur.extra_key):
        cur.load_state(dict(result.extra[cur.extra_key]))


def jump_curves(hooks: Hooks, result: Any) -> dict[str, list]:
    """``z`` (bar height / obstacle width), success rate and (Stage 2) novelty against samples."""
    from toolkit.policy.train import TIMES

    z_attr, z_hist = hooks.state["z_attr"], hooks.state["z_hist"]
    times = [float(t) for t in np.asarray(result.extra.get(TIMES, np.zeros(0)), dtype=np.float64).ravel()]
    if len(times) != len(z_hist):  # a checkpoint from before the times were kept
        times = [None] * len(z_hist)

    def point(s: float, v: float, t: Optional[float]) -> tuple:
        return (int(s), v, t) if t is not None else (int(s), v)

    out = {z_attr: [point(s, z, t) for (s, z, _), t in zip(z_hist, times)],
           "success_rate": [point(s, r, t) for (s, _, r), t in zip(z_hist, times) if math.isfinite(r)]}
    nov = np.asarray(result.extra.get("novelty_history", np.zeros((0, 2))), dtype=np.float64).reshape(-1, 2)
    if len(nov):
        out["novelty"] = [(int(s), float(v)) for s, v in nov]
    return out
