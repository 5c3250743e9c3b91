"""Learning curves of jump runs: mean return, success rate and bar height (or obstacle width) vs samples.

Reads the ``ppo.h5`` checkpoints that every jumping evaluation writes (``train.py``: history per
PPO iteration and the curriculum's ``z_history`` rows ``(samples, z, success rate)``; ``z`` is the
obstacle's width for ``task=obstacle`` and ``longjump``) and draws them side by side, one line per
file::

    jt study highjump curves RUN_WORKDIR/eval_0000/ppo.h5 OTHER/ppo.h5 \\
        --labels paper "small budget" --out curves.png

and prints a table of the values at a few sample counts.
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional, Sequence

import numpy as np

from toolkit.errors import JtError, one_line_errors
from toolkit.study import existing_file, parser, task_of, writable_file

PROG = "jt study highjump curves"
JUMPS = ("highjump", "obstacle", "longjump")  #: the tasks whose ppo.h5 holds the curriculum's curve


def read(path: str | Path) -> dict[str, np.ndarray]:
    """``{"samples", "mean_return", "success_rate", "bar_height"}`` ``(n_iterations,)`` of a ``ppo.h5``.

    Raises:
        JtError: one line: not an HDF5 file, or no jump curriculum's curve in it (another task's run).
    """
    import h5py

    try:
        with h5py.File(path, "r") as f:
            if "history/mean_return" not in f or "extra/z_history" not in f:
                raise JtError(f"{path}: no jump curriculum curve in it (extra/z_history); {PROG} reads the "
                              f"ppo.h5 of a task={'/'.join(JUMPS)} run")
            ret = np.asarray(f["history/mean_return"][()], dtype=float)
            z = np.asarray(f["extra/z_history"][()], dtype=float).reshape(-1, 3)
    except OSError as e:
        raise JtError(f"{path}: not a readable ppo.h5 ({e})") from None
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


@one_line_errors
def main(argv: Optional[Sequence[str]] = None) -> None:
    ap = parser(PROG, __doc__.split("\n")[0])
    ap.add_argument("files", nargs="+", metavar="PPO_H5",
                    help="ppo.h5 files of jump runs (<store>/work/<run id>/eval_0000/ppo.h5)")
    ap.add_argument("--labels", nargs="+", help="one label per file (default: each file's folder name)")
    ap.add_argument("--out", default="curves.png", help="the plot (.png; default curves.png)")
    a = ap.parse_args(argv)
    if a.labels is not None and len(a.labels) != len(a.files):
        raise JtError(f"--labels: {len(a.labels)} labels for {len(a.files)} files; give one per file")
    paths = [existing_file(f, "file") for f in a.files]
    for f, path in zip(a.files, paths):
        other = task_of(path)
        if other is not None and other not in JUMPS:
            raise JtError(f"{f}: a task={other} run; {PROG} reads task={'/'.join(JUMPS)} runs")
    curves = [read(p) for p in paths]
    out = writable_file(a.out, "--out", suffix=".png")
    labels = a.labels or [p.parent.name for p in paths]
    print(table(curves, labels))
    print(plot(curves, labels, out))


if __name__ == "__main__":
    main()
