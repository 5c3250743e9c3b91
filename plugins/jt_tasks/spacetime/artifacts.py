"""Artifacts of ``task=spacetime`` besides the policy layer's: the start distribution per iteration.

``write_start_sampling`` writes ``start_sampling.h5`` (``samples`` ``(n_it,)``, ``probs``, ``w``,
``count`` ``(n_it, n_segments)``: eq 11's start-segment probabilities, the segments' running
averages of the start targets, and eq 12's buffer sizes after each iteration, 002 §4.3) and
``start_sampling.png`` (the probabilities as an image: iteration down, segment across, and the
last iteration's as bars), ``com_bounds.png``, the Fig. 5 analogue: the final rollout's CoM
height against the clip phase with the reference and its ``com_y`` bounds, and
``motion_vs_reference.gif``: the final rollout (left) beside the reference clip played
kinematically at the same clip times (right), one frame per control step. ``style_measures``
gives a motion's mean kinetic energy (002 eq 4's) and hull volume (eq 5's), the evaluation's and
the reference's at the same clip times (``reference_bodies``), logged as ``style_*`` / ``ref_*``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np


def write_start_sampling(workdir: Path, h: dict[str, np.ndarray]) -> list[str]:
    """``start_sampling.h5`` and ``start_sampling.png`` in ``workdir`` from ``StartSampler.history()``."""
    from toolkit.store import h5

    workdir = Path(workdir)
    h5.write(workdir / "start_sampling.h5", {k: np.asarray(v, dtype=float) for k, v in h.items()},
             {"what": "002 eq 11 start-segment probabilities per PPO iteration", "n_segments": int(h["probs"].shape[1])})
    plot_start_sampling(h, workdir / "start_sampling.png")
    return ["start_sampling.h5", "start_sampling.png"]


def plot_start_sampling(h: dict[str, np.ndarray], out: Path) -> Path:
    """Two panels: p(k) per iteration (image) and the last iteration's p(k) with w_k (bars)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    probs, w = np.asarray(h["probs"]), np.asarray(h["w"])
    n = probs.shape[1]
    fig, (a, b) = plt.subplots(1, 2, figsize=(8, 3))
    im = a.imshow(probs, aspect="auto", origin="lower", cmap="viridis", interpolation="nearest",
                  extent=(0, 1, 0.5, probs.shape[0] + 0.5))
    a.set_xlabel("start phase (segment)")
    a.set_ylabel("PPO iteration")
    a.set_title("eq 11: p(segment)")
    fig.colorbar(im, ax=a)
    x = (np.arange(n) + 0.5) / n
    b.bar(x, probs[-1], width=0.9 / n, label="p(k), last iteration")
    b.axhline(1.0 / n, color="gray", lw=0.8, ls="--", label="uniform")
    b.set_xlabel("start phase")
    b.set_ylabel("p(k)")
    b2 = b.twinx()
    b2.plot(x, w[-1], "o-", color="C3", ms=3, label="w_k")
    b2.set_ylabel("w_k (start target)")
    b.legend(loc="upper left", fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=80)
    plt.close(fig)
    return Path(out)


def com_height_data(env: Any, times: np.ndarray, com: np.ndarray, n_grid: int = 200) -> dict[str, np.ndarray]:
    """What ``com_bounds.png`` draws, from a rollout of ``env`` (still open): ``phase`` and
    ``com_y`` ``(n,)`` of the rollout's states, the reference's CoM height ``ref_phase`` /
    ``ref_com_y`` ``(n_grid,)`` over one cycle and the channel's width ``width`` ``(n_grid,)`` there
    (a phase table's, else constant; inf: off)."""
    ref = env.ref
    times = np.asarray(times, dtype=float).reshape(-1)
    phase = np.array([ref.phase(env.t0 + t) for t in times])
    grid = np.linspace(0.0, 1.0, n_grid)
    ref_y = np.array([ref.sample(g * ref.period).com[1] for g in grid])
    ch = list(env.names).index("com_y")
    width = np.array([float(env.widths_at(g)[ch]) for g in grid])
    return {"phase": phase, "com_y": np.asarray(com, dtype=float).reshape(-1, 3)[:, 1], "ref_phase": grid,
            "ref_com_y": ref_y, "width": width}


def plot_com_bounds(d: dict[str, np.ndarray], out: Path, title: str = "") -> Path:
    """The Fig. 5 analogue (002): CoM height against phase, the reference (green), its bounds ±
    width (red) and the rollout's states (blue dots)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 3))
    ax.plot(d["ref_phase"], d["ref_com_y"], color="green", lw=1.5, label="reference")
    w = np.broadcast_to(np.asarray(d["width"], dtype=float), np.shape(d["ref_phase"]))
    if np.isfinite(w).any():  # off (inf) stretches of a phase table are left blank
        w = np.where(np.isfinite(w), w, np.nan)
        for sgn in (-1, 1):
            ax.plot(d["ref_phase"], d["ref_com_y"] + sgn * w, color="red", lw=1.0, label="bounds" if sgn > 0 else None)
    ax.scatter(d["phase"], d["com_y"], s=6, color="C0", label="policy", zorder=3)
    ax.set_xlabel("phase")
    ax.set_ylabel("CoM height (m)")
    ax.set_xlim(0, 1)
    ax.set_title(title or "CoM height vs phase (002 Fig. 5)", fontsize=9)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(out, dpi=80)
    plt.close(fig)
    return Path(out)


def reference_frames(env: Any, times: np.ndarray, width: int, height: int) -> list[np.ndarray]:
    """The reference of ``env`` (still open) posed at clip times ``env.t0 + times`` and rendered
    ``(height, width, 3)`` with the env's camera, in a second simulator of the env's config (the
    env's own is untouched): kinematically, each pose set by ``Simulator.reset``, nothing
    stepped; a pose that dips into the ground is shown lifted out of it, as an episode's start is
    (``SpacetimeEnv``). About 6 ms a frame at 120 x 90 on 2 shared cores (4 s for a 20 s rollout)."""
    from toolkit.render import Camera

    from toolkit.policy.env import load_simulator

    sim = load_simulator(env.spec_.sim)
    camera = Camera(**env.CAMERA) if env.CAMERA else None
    out = []
    try:
        for t in np.asarray(times, dtype=float).reshape(-1):
            ref = env.ref.sample(env.t0 + float(t))
            sim.reset(ref.q, ref.qd)
            low = min(float(sim.aabb(i)[0][1]) for i in range(-1, int(sim.n_links)))
            if low < 0.0:
                q = np.array(ref.q, dtype=float)
                q[1] += float(env.spec_.ground_clearance) - low
                sim.reset(q, ref.qd)
            out.append(np.asarray(sim.render(int(width), int(height), camera))[..., :3].astype(np.uint8))
    finally:
        sim.close()
    return out


def style_measures(bodies: list, masses: np.ndarray, hz: float) -> dict[str, float]:
    """Mean style measures of a motion (002 §3.3) from its control steps ``bodies`` = ``[(link CoMs
    (n_links + 1, 3), joint origins (n_links, 3)), ...]`` at ``hz``, as the style terms measure a
    state: ``energy`` (J, eq 4's kinetic energy less the horizontal CoM part, link velocities by
    differences over a step, from the second step on) and ``volume`` (m³, eq 5's convex hull of the
    joint origins); NaN for an empty motion."""
    from toolkit.motion.style import hull_volume, kinetic_energy

    if not bodies:
        return {"energy": math.nan, "volume": math.nan}
    vols = [hull_volume(j) for _, j in bodies]
    links = [np.asarray(p, dtype=float) for p, _ in bodies]
    ens = [kinetic_energy((b - a) * hz, masses) for a, b in zip(links[:-1], links[1:])]
    return {"energy": float(np.mean(ens)) if ens else math.nan, "volume": float(np.mean(vols))}


def reference_bodies(env: Any, times: np.ndarray) -> list:
    """The reference of ``env`` (still open) posed at clip times ``env.t0 + times`` in a second
    simulator (kinematically, as ``reference_frames``): ``[(link CoMs, joint origins), ...]`` for
    ``style_measures``."""
    from toolkit.policy.env import load_simulator

    sim = load_simulator(env.spec_.sim)
    out = []
    try:
        for t in np.asarray(times, dtype=float).reshape(-1):
            ref = env.ref.sample(env.t0 + float(t))
            sim.reset(ref.q, ref.qd)
            out.append((sim.link_states()[0], sim.link_poses(range(env.n_links))[0]))
    finally:
        sim.close()
    return out


def write_motion_vs_reference(workdir: Path, policy: list, reference: list, fps: float = 30.0,
                              gap: int = 2) -> list[str]:
    """``motion_vs_reference.gif`` in ``workdir``: each policy frame (left) and reference frame
    (right) side by side with a ``gap`` px white column, at ``fps``, at the rendered size (not
    enlarged as ``motion.gif`` is: twice the frames to encode, it would cost 10 s for a 20 s
    rollout at 120 x 90); the names written (none without frames)."""
    from toolkit.render import save_animation

    if not policy or len(policy) != len(reference):
        return []
    pol = [np.asarray(f)[..., :3].astype(np.uint8) for f in policy]
    white = np.full((pol[0].shape[0], int(gap), 3), 255, np.uint8)
    frames = [np.concatenate([p, white, np.asarray(r)[..., :3].astype(np.uint8)], axis=1)
              for p, r in zip(pol, reference)]
    save_animation(frames, Path(workdir) / "motion_vs_reference.gif", fps, min_width=0)
    return ["motion_vs_reference.gif"]
