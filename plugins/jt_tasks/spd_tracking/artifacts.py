"""Files of an ``spd_tracking`` evaluation: the HDF5 record, the error plot, the filmstrip/GIF."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Sequence

import numpy as np

FORMAT = "jt.spd_tracking"
VERSION = 1


def rate_key(rate_hz: float) -> str:
    """``30 -> 'dt30'`` (1/dt in Hz; ``'.'`` becomes ``'p'``): a legal MLflow / HDF5 name."""
    text = f"{float(rate_hz):g}".replace(".", "p")
    return f"dt{text}"


def write_h5(path: Path, runs: Sequence[Any], info: dict, config_yaml: str) -> Path:
    """The HDF5 record (atomic, ``toolkit.store.h5.write``).

    Layout: ``rates_hz`` ``(n_rates,)``, ``dt`` ``(n_rates,)``, per rate a group ``runs/dt<N>``
    with ``time`` ``(n,)``, ``error`` ``(n,)`` (m; NaN after divergence), ``ee_sim`` and
    ``ee_ref`` ``(n, 3)`` (end-effector minus root, world frame), ``diverged``, ``reason``,
    ``n_steps``, ``fps`` / ``spd_share`` (from median step times) and ``fps_mean`` /
    ``spd_share_mean`` (from total times); ``fps`` and ``spd_share_pct`` of the timing run;
    ``model``
    (name, dof, depth, n_q); root attributes: format, version, backend, character, motion,
    end-effector, config (YAML).
    """
    from toolkit.store import h5

    data: dict[str, Any] = {
        "rates_hz": np.array([r.rate_hz for r in runs]),
        "dt": np.array([1.0 / r.rate_hz for r in runs]),
        "runs": {rate_key(r.rate_hz): {
            "time": r.time, "error": r.error, "ee_sim": r.ee_sim, "ee_ref": r.ee_ref,
            "diverged": bool(r.diverged), "reason": r.reason or "", "n_steps": int(r.n_steps),
            "fps": float(r.fps), "spd_share": float(r.spd_share), "wall_s": float(r.wall_s),
            "fps_mean": r.substeps / r.substep_s if r.substep_s > 0 else np.nan,
            "spd_share_mean": r.spd_s / r.substep_s if r.substep_s > 0 else np.nan,
        } for r in runs},
        "fps": float(info["fps"]),
        "fps_rate_hz": float(info["fps_rate_hz"]),
        "fps_steps": int(info["fps_steps"]),
        "spd_share_pct": float(info["spd_share_pct"]),
        "model": {"name": info["character"], "dof": int(info["dof"]), "depth": int(info["depth"]),
                  "n_q": int(info["n_q"])},
    }
    attrs = {"format": FORMAT, "version": VERSION, "backend": info["backend"],
             "character": info["character"], "motion": info["motion"],
             "end_effector": info["end_effector"], "config": config_yaml}
    return h5.write(path, data, attrs=attrs)


def plot_errors(path: Path, runs: Sequence[Any], title: str) -> Path:
    """Error vs time, one curve per dt (thesis Figs 2.4 / 2.5); a cross marks a divergence."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.0, 3.6))
    for r in sorted(runs, key=lambda r: r.rate_hz):
        label = f"dt = 1/{r.rate_hz:g} s" + (" (diverged)" if r.diverged else "")
        line, = ax.plot(r.time, 100.0 * r.error, lw=1.2, label=label)
        if r.diverged:  # a cross at the last finite error
            k = max(r.n_steps - 1, 0)
            y = 100.0 * float(np.nan_to_num(r.error[k])) if r.n_steps else 0.0
            ax.plot([r.time[k]], [y], "x", color=line.get_color(), ms=8)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("tracking error (cm)")
    ax.set_title(title, fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def save_frames(workdir: Path, frames: Sequence[np.ndarray], n_strip: int, fps: float) -> list[str]:
    """``filmstrip.png`` (``n_strip`` evenly spaced frames) and ``tracking.gif``; file names."""
    from toolkit.render import filmstrip, pick, save_animation, save_png

    if not frames:
        return []
    save_png(filmstrip(pick(list(frames), n_strip)), workdir / "filmstrip.png")
    save_animation(list(frames), workdir / "tracking.gif", fps=fps)
    return ["filmstrip.png", "tracking.gif"]


def metrics_of(runs: Sequence[Any], fps: float, share: float) -> dict[str, float]:
    """``fps``, ``spd_share_pct``, ``err_mean_dt<N>``, ``err_max_dt<N>``, ``diverged_dt<N>``,
    ``n_diverged`` (errors are NaN for a diverged dt)."""
    out = {"fps": float(fps), "spd_share_pct": 100.0 * float(share)}
    n_div = 0
    for r in runs:
        k = rate_key(r.rate_hz)
        ok = not r.diverged and r.n_steps > 0
        out[f"err_mean_{k}"] = float(np.nanmean(r.error)) if ok else math.nan
        out[f"err_max_{k}"] = float(np.nanmax(r.error)) if ok else math.nan
        out[f"diverged_{k}"] = float(r.diverged)
        n_div += int(r.diverged)
    out["n_diverged"] = float(n_div)
    return out
