"""What early termination by the bounds saves: the FFC alone, bounds off, per clip (002 §3.2; issue 12).

Under a fixed policy, the feed-forward controller alone (zero correction, ``action=ffc_fbc``),
each clip is played from ``n_starts`` evenly spread phases with the bounds *off* (the
evaluation's set-up: only a forbidden ground contact or the time limit ends the episode), and
the 22-channel difference to the reference is checked after every control step (issue 12,
measurement 3). Per episode:

* ``first``: the control step of the first bound violation (None: never out of bounds);
* ``after``: control steps from the first violation to the episode's end;
* ``lost``: those of them after the *last* step inside the bounds — the samples that never
  return inside, which termination at the first violation saves from being trained on.

The share ``lost / after`` (summed over starts) is what the bounds save::

    jt study spacetime bounds --clips walk run jump roll cartwheel backflip dance_a --starts 5 --seconds 4
"""

from __future__ import annotations

import math
from typing import Any, Optional, Sequence

import numpy as np

from toolkit.errors import JtError, one_line_errors
from toolkit.study import parser

PROG = "jt study spacetime bounds"

CLIPS = ("walk", "run", "jump", "roll", "cartwheel", "backflip", "dance_a")


def episode(env: Any, phase: float, max_steps: int) -> dict[str, Optional[int]]:
    """One bounds-off episode of the zero-correction policy from ``phase``: ``steps``, ``first``,
    ``after``, ``lost`` (see the module docstring)."""
    from jt_tasks.spacetime import bounds as bd

    env.reset(seed=0, options={"phase": float(phase), "evaluate": True})
    inside: list[bool] = []
    zero = np.zeros(env.action_space.shape, np.float32)
    for _ in range(max_steps):
        _, _, te, tr, _ = env.step(zero)
        inside.append(not bd.violations(env.difference(), env.widths_at(env.ref.phase(env.clip_time)), env.names))
        if te or tr:
            break
    return tally(inside)


def tally(inside: Sequence[bool]) -> dict[str, Optional[int]]:
    """``steps``, ``first``, ``after``, ``lost`` of one episode's per-step inside-the-bounds flags."""
    inside = [bool(x) for x in inside]
    out_idx = [i for i, ok in enumerate(inside) if not ok]
    if not out_idx:
        return {"steps": len(inside), "first": None, "after": 0, "lost": 0}
    first = out_idx[0]
    last_in = max([i for i, ok in enumerate(inside) if ok] or [-1])
    return {"steps": len(inside), "first": first, "after": len(inside) - first,
            "lost": len(inside) - max(last_in + 1, first)}


def study(clips: Sequence[str] = CLIPS, n_starts: int = 5, seconds: float = 4.0) -> list[dict[str, Any]]:
    """Per clip: ``clip``, ``episodes``, ``steps``, ``violated`` (episodes that left the bounds),
    ``first_s`` (median time of the first violation), ``after``, ``lost``, ``share_lost``."""
    from toolkit.config import compose

    from toolkit import plugins

    rows = []
    for clip in clips:
        cfg = compose(["task=spacetime", f"task.clip={clip}", f"task.eval_time_limit={seconds}"])
        env = plugins.load("task", "spacetime")(cfg).make_env(seed=0)
        try:
            max_steps = int(round(seconds * env.control_hz))
            eps = [episode(env, k / n_starts, max_steps) for k in range(n_starts)]
            hz = env.control_hz
        finally:
            env.close()
        firsts = [e["first"] for e in eps if e["first"] is not None]
        after, lost = sum(e["after"] for e in eps), sum(e["lost"] for e in eps)
        rows.append({"clip": clip, "episodes": len(eps), "steps": sum(e["steps"] for e in eps),
                     "violated": len(firsts), "first_s": float(np.median(firsts) + 1) / hz if firsts else float("nan"),
                     "after": after, "lost": lost, "share_lost": lost / after if after else float("nan")})
    return rows


@one_line_errors
def main(argv: Optional[Sequence[str]] = None) -> None:
    from jt_tasks.spacetime.reference import resolve_clip

    ap = parser(PROG, __doc__.split("\n")[0])
    ap.add_argument("--clips", nargs="+", default=list(CLIPS), help=f"the clips (default: {' '.join(CLIPS)})")
    ap.add_argument("--starts", type=int, default=5, help="start phases k / starts per clip (default 5)")
    ap.add_argument("--seconds", type=float, default=4.0, help="seconds per episode at most (default 4)")
    args = ap.parse_args(argv)
    if args.starts < 1:
        raise JtError(f"--starts={args.starts}: at least 1 start phase")
    if not (math.isfinite(args.seconds) and args.seconds > 0):
        raise JtError(f"--seconds={args.seconds}: a finite number of seconds > 0 (e.g. --seconds 3)")
    for clip in args.clips:  # every clip found before the first episode
        try:
            resolve_clip(clip)
        except JtError as e:
            raise JtError(f"--clips: {e}") from None
    rows = study(args.clips, args.starts, args.seconds)
    print("| clip | episodes | steps | left the bounds | first violation (median, s) | steps after it | never back inside | share |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['clip']} | {r['episodes']} | {r['steps']} | {r['violated']} | {r['first_s']:.2f} | {r['after']} | "
              f"{r['lost']} | {r['share_lost']:.2f} |")


if __name__ == "__main__":
    main()
