"""Learning curves of jump trainings: mean return, success rate and bar height against samples.

Reads the ``ppo.h5`` checkpoints that every jumping evaluation writes (``train.py``; history per
PPO iteration and the curriculum's ``z_history`` rows ``(samples, z, success rate)``) and draws
them side by side, one line per file:

    python -m jt_tasks.jumping.curves RUN_WORKDIR/eval_0000/ppo.h5 OTHER/ppo.h5 \\
        --labels paper "small budget" --out curves.png

and prints a table of the values at a few sample counts.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any, Sequence

import numpy as np


def read(path: str | Path) -> dict[str, np.ndarray]:
    """``{"samples", "mean_return", "success_rate", "bar_height"}`` ``(n_iterations,)`` of a ``ppo.h5``."""
    import h5py

    with h5py.File(path, "r") as f:
        ret = np.asarray(f["history/mean_return"][()], dtype=float)
        z = np.asarray(f["extra/z_history"][()], dtype=float).reshape(-1, 3)
    n = min(len(ret), len(z))
    return {"samples": z[:n, 0], "mean_return": ret[:n], "bar_height": z[:n, 1], "success_rate": z[:n, 2]}


def plot(curves: Sequence[dict[str, np.ndarray]], labels: Sequence[str], out: str | Path) -> Path:
    """Three panels (mean return, success rate, bar height vs samples) to ``out`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(12, 3.4))
    for c, label in zip(curves, labels):
        for ax, key in zip(axes, ("mean_return", "success_rate", "bar_height")):
            ax.plot(c["samples"], c[key], label=label)
    for ax, title in zip(axes, ("mean episode return", "success rate", "bar height z (m)")):
        ax.set_xlabel("samples")
        ax.set_title(title, fontsize=9)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return Path(out)


def table(curves: Sequence[dict[str, np.ndarray]], labels: Sequence[str], points: int = 6) -> str:
    """Markdown rows ``label | samples | mean return | success | z`` at ``points`` evenly spaced iterations."""
    rows = ["| run | samples | mean return | success rate | bar height (m) |", "|---|---|---|---|---|"]
    for c, label in zip(curves, labels):
        idx = np.unique(np.linspace(0, len(c["samples"]) - 1, points).round().astype(int))
        for i in idx:
            rows.append(f"| {label} | {int(c['samples'][i])} | {c['mean_return'][i]:.3f} | "
                        f"{c['success_rate'][i]:.2f} | {c['bar_height'][i]:.2f} |")
    return "\n".join(rows)


def main(argv: Any = None) -> None:  # pragma: no cover - command line
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--labels", nargs="+")
    ap.add_argument("--out", default="curves.png")
    a = ap.parse_args(argv)
    labels = a.labels or [Path(f).parent.name for f in a.files]
    curves = [read(f) for f in a.files]
    print(table(curves, labels))
    print(plot(curves, labels, a.out))


if __name__ == "__main__":  # pragma: no cover
    main()
