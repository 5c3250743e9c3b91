"""Survival against samples of task=spacetime runs (002 Table 1's curve), one line per run.

Every run keeps Table 1's evaluation rows in its ``ppo.h5`` (``extra/eval_history``: samples, mean
survival over the start phases, share of starts that survived, worst start; ``training.py``), so a
finished, stopped or running run can be drawn::

    jt study spacetime survival RUN[=LABEL] [RUN[=LABEL] ...] --store DIR --out FILE.png

``RUN`` is a run id (the store's), a folder holding ``ppo.h5`` or the file (a running or stopped
run's newest checkpoint is ``<store>/work/<run id>/eval_0000/ppo.h5``). The plot draws each run's
mean survival (solid) and worst start (dotted) against samples, with the 20 s of Table 1; the
printout gives each run's ``samples_to_20s`` (the first evaluation at which every start lasted the
time limit, or ``-``) and its last evaluation.
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional, Sequence

import numpy as np

from toolkit.errors import JtError, one_line_errors
from toolkit.study import parser, require_task, writable_file

PROG = "jt study spacetime survival"


def read_rows(ppo_h5: Path) -> np.ndarray:
    """The run's evaluation rows ``(n_evaluations, 4)``: samples, mean s, share survived, min s.

    Raises:
        JtError: the file has no Table 1 evaluation (not a ``task=spacetime`` run, or none yet).
    """
    import h5py

    try:
        with h5py.File(ppo_h5, "r") as f:
            key = "extra/eval_history"
            rows = np.asarray(f[key][:], dtype=float) if key in f else np.zeros((0, 4))
    except OSError as e:
        raise JtError(f"{ppo_h5}: not a readable ppo.h5 ({e})") from None
    if rows.ndim != 2 or rows.shape[1] != 4 or not len(rows):
        raise JtError(f"{ppo_h5}: no Table 1 evaluation in it (a task=spacetime run evaluates every "
                      "task.eval_every iterations; this one has none yet)")
    return rows


def summary(label: str, rows: np.ndarray) -> str:
    """One line: the run's label, samples to 20 s and its last evaluation."""
    from jt_tasks.spacetime.training import samples_to_20s

    hit = samples_to_20s(rows)
    last = rows[-1]
    to20 = "-" if hit is None else f"{hit / 1e6:.2f} M"
    return (f"{label:24s} samples_to_20s {to20:>8s}   last: {last[0] / 1e6:.2f} M samples, "
            f"mean {last[1]:.2f} s, worst {last[3]:.2f} s ({len(rows)} evaluations)")


def plot(curves: Sequence[tuple[str, np.ndarray]], out: Path, title: str = "", limit: float = 20.0) -> Path:
    """Draw ``curves`` (``(label, rows)``) into ``out``: mean survival solid, worst start dotted."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 3.6))
    for i, (label, rows) in enumerate(curves):
        color = f"C{i % 10}"
        ax.plot(rows[:, 0] / 1e6, rows[:, 1], "-", color=color, label=f"{label} (mean of the starts)")
        ax.plot(rows[:, 0] / 1e6, rows[:, 3], ":", color=color, lw=1.0, label=f"{label} (worst start)")
    ax.axhline(limit, color="k", lw=0.8, ls="--")
    ax.set_xlabel("samples (M)")
    ax.set_ylabel("survival (s), bounds off")
    ax.set_ylim(0, limit * 1.05)
    if title:
        ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


@one_line_errors
def main(argv: Optional[Sequence[str]] = None) -> None:
    from toolkit.store.resolve import resolve

    ap = parser(PROG, __doc__.split("\n")[0])
    ap.add_argument("runs", nargs="+", metavar="RUN[=LABEL]",
                    help="task=spacetime run ids, folders holding ppo.h5 or the files, each with an optional =label")
    ap.add_argument("--store", default=None, help="the store the runs are in")
    ap.add_argument("--out", default=None, help="the plot (.png); without it only the summary is printed")
    ap.add_argument("--title", default="", help="the plot's title")
    args = ap.parse_args(argv)
    if args.out is not None and Path(args.out).suffix.lower() != ".png":
        raise JtError(f"--out={args.out}: the plot is a .png file (e.g. --out survival.png)")
    curves = []
    for item in args.runs:
        ref, _, label = item.partition("=")
        found = resolve(ref, artifact="ppo.h5", store=args.store, what="run", label="trained policy")
        require_task(found, ref, "spacetime", PROG)
        rows = read_rows(found.path)
        curves.append((label or (found.run_id[:8] if found.run_id else Path(ref).stem), rows))
    out = None if args.out is None else writable_file(args.out, "--out")
    for label, rows in curves:
        print(summary(label, rows))
    if out is not None:
        print(f"plot: {plot(curves, out, args.title)}")


if __name__ == "__main__":
    main()
