"""Where a trained task=getup policy stops, from each kind of start, beside the clips played open loop.

Issue 29: what a trained ``task=getup`` policy does from each kind of start, and how far the clips
themselves get without feedback.

``jt study getup policy RUN --store DIR [--out FOLDER]`` prints, for the run's policy (its
``ppo.h5``), the deterministic episode from the clip starts at 0, 25, 50, 75 and 90 % of the clip
(the curve's clock set there, ``task.rsi``'s starts) and from standing: control steps lived, why it
ended, the highest neck height, whether it got up; then the same for the open-loop clip (every PD
target the clip's pose at that time, no policy: ``open_loop_clip``); and, with ``--out``, plots the
run's per-iteration history and its evaluations from perturbed clip starts against samples.
``--stand SECONDS`` measures standing balance instead: the deterministic policy from every curve's
standing start, given ``SECONDS`` of standing (``task.t_stand``, no start noise), control steps
until the episode ends (``standing_balance``).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Optional, Sequence

import numpy as np

from toolkit.errors import JtError, one_line_errors
from toolkit.study import parser, writable_folder

PROG = "jt study getup policy"

FRACTIONS = (0.0, 0.25, 0.5, 0.75, 0.9)  #: clip starts, as shares of the clip's duration


def open_loop_clip(clip: str, sim_groups: dict, t_stand: float = 3.0, mirrored: bool = False) -> dict[str, float]:
    """The get-up clip tracked without feedback: from its first pose, every control step's PD target
    is the clip's pose at that time (then its last pose for ``t_stand`` s), the root unactuated.

    Returns:
        ``h_max`` (m, the highest neck height), ``t_h_max`` (s), ``h_end`` (m, at the end),
        ``duration`` (s, the clip's).
    """
    from jt_tasks.getup import features as F
    from jt_tasks.getup.curves import load_getup_clip
    from jt_tasks.getup.initial import clip_pose
    from toolkit.policy.env import load_simulator
    from jt_tasks.takeoff.state import reference_state

    c = load_getup_clip(clip, mirrored)
    t0, T = float(c.times[0]), float(c.times[-1] - c.times[0])
    sim = load_simulator(sim_groups)
    try:
        q, qd = clip_pose(clip, mirrored, frame=0)
        sim.reset(q, qd)
        hz = float(sim.control_hz)
        hs = []
        for k in range(int(round((T + t_stand) * hz))):
            _, _, joints, _, _, _ = reference_state(c, t0 + min(k / hz, T - 1e-3))
            now, _ = sim.state()
            sim.step(np.concatenate([now[:7], joints]))
            hs.append(float(F.measure(sim, 5, 0.25)["features"][0]))
    finally:
        sim.close()
    h = np.array(hs)
    return {"h_max": float(h.max()), "t_h_max": float(h.argmax() / hz), "h_end": float(h[-1]), "duration": T}


def episode(env: Any, model: Any, options: dict) -> dict[str, Any]:
    """One deterministic episode: steps, the end's reason, the highest neck height after a step
    (0 at least), got_up, success."""
    from toolkit.policy.episodes import rollout

    ro = rollout(env, model, lambda e: {"h": float(e.measure()["features"][0])}, options=options)
    info, h_max = ro.info, float(max([0.0, *ro.series["h"][1:]]))  # not the start's height
    return {"steps": ro.steps, "reason": str(info.get("reason", "")), "h_max": h_max,
            "got_up": float(info.get("got_up", 0.0)), "success": float(info.get("success", 0.0))}


def policy_starts(env: Any, model: Any, curves: tuple[str, ...] = ("facedown", "faceup"),
                  fractions: tuple[float, ...] = FRACTIONS) -> list[dict[str, Any]]:
    """``episode`` from each clip start at ``fractions`` of the clip and from standing, for each
    curve; a row's ``needs`` is the control steps a success lasts from there (the rest of the clip
    and ``t_stand``)."""
    rows = []
    for name in curves:
        T = next(c for c in env.curves if c.name == name).duration
        for frac in fractions:
            needs = int(round(((1.0 - frac) * T + env.spec_.t_stand) * env.control_hz))
            rows.append({"curve": name, "start": f"clip at {frac:.0%}", "needs": needs,
                         **episode(env, model, {"kind": "clip", "curve": name, "at": frac * T})})
        rows.append({"curve": name, "start": "standing", **episode(env, model, {"kind": "standing", "curve": name})})
    return rows


def standing_balance(env: Any, model: Any, seconds: float) -> list[dict[str, Any]]:
    """``episode`` from every curve's standing start with ``seconds`` s of standing (the env's
    ``t_stand`` set for it, restored after): how long the policy balances beyond its training
    episodes (``T_stand`` = 3 s, 003 §5.6). Rows carry ``curve``, ``steps`` and ``of`` (the limit)."""
    old = env.spec_.t_stand
    env.spec_.t_stand = float(seconds)
    try:
        limit = int(round(float(seconds) * env.control_hz))
        return [{"curve": c.name, "of": limit, **episode(env, model, {"kind": "standing", "curve": c.name})}
                for c in env.curves]
    finally:
        env.spec_.t_stand = old


def plot_history(ppo_h5: Path, out: Path) -> Optional[Path]:
    """``getup_history.png``: the training return rate and the share ended early per iteration, and
    the evaluations' success / got-up shares from perturbed clip starts, against samples."""
    import h5py
    import matplotlib

    from jt_tasks.getup.task import HISTORY

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def col(name: str) -> int:  # the history's rows are (samples, *HISTORY)
        return 1 + HISTORY.index(name)

    with h5py.File(ppo_h5, "r") as f:
        hist = f["extra/getup_history"][:] if "extra/getup_history" in f else None
        ev = f["extra/eval_history"][:] if "extra/eval_history" in f else None
    if hist is None or not len(hist):
        return None
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.2))
    ax[0].plot(hist[:, 0] / 1e6, hist[:, col("task_return_rate")], label="task return rate (ground starts)")
    ax[0].plot(hist[:, 0] / 1e6, hist[:, col("r_task_mean")], label="mean r_task")
    ax[0].plot(hist[:, 0] / 1e6, hist[:, col("early")], label="share ended early")
    ax[0].set_xlabel("samples (M)")
    ax[0].legend(fontsize=7)
    if ev is not None and len(ev):
        ax[1].plot(ev[:, 0] / 1e6, ev[:, 1], "o-", label="success")
        ax[1].plot(ev[:, 0] / 1e6, ev[:, 2], "s--", label="got up")
    ax[1].set_ylim(-0.05, 1.05)
    ax[1].set_xlabel("samples (M)")
    ax[1].set_title("deterministic, perturbed clip starts", fontsize=8)
    ax[1].legend(fontsize=7)
    fig.tight_layout()
    path = out / "getup_history.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


@one_line_errors
def main(argv: Optional[Sequence[str]] = None) -> None:
    from omegaconf import OmegaConf

    from toolkit import plugins
    from toolkit.config import validate
    from toolkit.rl.checkpoint import load_policy
    from toolkit.store.resolve import resolve, run_config

    ap = parser(PROG, __doc__.split("\n")[0])
    ap.add_argument("run", help="a task=getup run id (its best evaluation), a folder or a ppo.h5")
    ap.add_argument("--store", default=None, help="the store the run is in")
    ap.add_argument("--out", default=None, help="a folder for getup_history.png")
    ap.add_argument("--config", default=None, help="the run's config.yaml (default: the one beside its ppo.h5)")
    ap.add_argument("--stand", type=float, default=None, metavar="SECONDS",
                    help="standing balance only: standing starts given SECONDS of standing")
    ap.add_argument("--at", type=float, nargs="+", default=list(FRACTIONS), metavar="FRACTION",
                    help="clip starts at these fractions of the clip, in [0, 1) (default: 0 0.25 0.5 0.75 0.9)")
    args = ap.parse_args(argv)
    if args.stand is not None and not (math.isfinite(args.stand) and args.stand > 0):
        raise JtError(f"--stand={args.stand}: the seconds of standing must be a finite number > 0 (e.g. --stand 10)")
    bad = [a for a in args.at if not (math.isfinite(a) and 0.0 <= a < 1.0)]
    if bad:
        raise JtError(f"--at={bad[0]}: a clip start is a fraction of the clip in [0, 1) (e.g. --at 0.5 0.75)")
    ref = resolve(args.run, artifact="ppo.h5", store=args.store, what="run", label="trained policy")
    cfg = validate(OmegaConf.load(run_config(ref.path, args.config)))
    if cfg.task.name != "getup":
        raise JtError(f"{args.run}: a task={cfg.task.name} run; {PROG} reads task=getup runs")
    out = None if args.out is None else writable_folder(args.out, "--out")
    task = plugins.load("task", "getup")(cfg)
    env = task.make_env(None, seed=0)
    try:
        model = load_policy(ref.path)
        if args.stand is not None:
            for r in standing_balance(env, model, args.stand):
                print(f"standing {r['curve']:16s} {r['steps']:4d} of {r['of']} steps  ({r['reason']})")
            return
        for r in policy_starts(env, model, fractions=tuple(args.at)):
            of = f" of {r['needs']}" if "needs" in r else ""
            print(f"policy   {r['curve']:9s} {r['start']:12s} {r['steps']:4d}{of} steps  h_max {r['h_max']:.2f} m  "
                  f"got_up {r['got_up']:.0f}  success {r['success']:.0f}  ({r['reason']})")
        sim_groups = env.spec_.sim
    finally:
        env.close()
    for clip in ("getup_facedown", "getup_faceup"):
        o = open_loop_clip(clip, sim_groups)
        print(f"open loop {clip}: h_max {o['h_max']:.2f} m at {o['t_h_max']:.2f} s of {o['duration']:.2f}, "
              f"h at the end {o['h_end']:.2f} m")
    if out is not None:
        print(plot_history(Path(ref.path), out))


if __name__ == "__main__":
    main()
