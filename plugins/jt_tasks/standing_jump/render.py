"""Pictures: filmstrips of jumps (the planar world's renderer, side view) and the Pareto-front plot.

The filmstrip re-simulates a parameter vector, keeps the pose at the start of each phase and at
the apex (as ``004`` Fig. 9 does: "capturing the pose at the beginning of each phase"), renders
each pose from the side and lays the frames out in one row. Natural jumps are drawn brown,
supernatural ones blue (the paper's colour code, §5). The front plot is the analogue of ``004``
Fig. 8: every sample as a black circle, the non-dominated ones joined by a green line.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Optional, Sequence

import numpy as np

BROWN = (0.55, 0.36, 0.2, 1.0)
BLUE = (0.2, 0.4, 0.85, 1.0)


def render_poses(qs: Sequence[Sequence[float]], rgba=BROWN, width: int = 160, height: int = 240,
                 mass: float = 80.0, body_height: float = 1.60, sim: str = "bullet") -> list[np.ndarray]:
    """Render joint-position vectors ``(19,)`` of the character, side view, one image each.

    Args:
        qs: joint positions, one ``(19,)`` vector per image (world joint order).
        rgba: the character's colour.
        width: image width, px.
        height: image height, px.
        mass: character mass, kg.
        body_height: character height, m.
        sim: registry name of the simulator plugin with the planar world (``bullet``).

    Returns:
        RGB images ``(height, width, 3)`` uint8.
    """
    from jt_tasks.standing_jump.model import build_body
    from jt_tasks.standing_jump.simulate import planar_world

    body = build_body(mass, body_height)
    world = planar_world(body, 1.0, 1000.0, rgba, sim)
    try:
        names = world.joint_names
        images = []
        for q in qs:
            world.reset_joints(q)
            x = q[names.index("root_x")]
            z = max(1.0, q[names.index("root_z")] + 0.25)
            images.append(world.render(width, height, eye=[x, -4.2, z], target=[x, 0.0, z]))
        return images
    finally:
        world.close()


def filmstrip(point: dict[str, float], path: Path, title: str, settings=None, width: int = 160,
              height: int = 240) -> Path:
    """Simulate ``point`` and save a one-row filmstrip PNG of its phases to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from jt_tasks.standing_jump.simulate import simulate

    res = simulate(point, settings, record=True)
    rgba = BROWN if res.natural else BLUE
    kw = {} if settings is None else {"mass": settings.mass, "body_height": settings.height,
                                      "sim": settings.sim}
    images = render_poses([q for _, q in res.snapshots], rgba, width, height, **kw)
    k = max(len(images), 1)
    fig, axes = plt.subplots(1, k, figsize=(1.3 * k * width / 160, 2.3 * height / 240), squeeze=False)
    for ax, img, (label, _) in zip(axes[0], images, res.snapshots):
        ax.imshow(img)
        ax.set_title(label, fontsize=8)
        ax.axis("off")
    fig.suptitle(f"{title}: head apex {res.height:.2f} m, "
                 f"{'natural' if res.natural else f'g0 {res.takeoff_gravity:.2f} m/s² for {res.assist_time:.2f} s'}"
                 f"{'' if res.success else ' — FAILED: ' + res.reason}", fontsize=8)
    return _save(fig, path)


def animation(point: dict[str, float], path: Path, settings=None, width: int = 160, height: int = 240,
              fps: float = 30.0) -> Path:
    """Simulate ``point`` and save the whole jump, one frame every ``1/fps`` s, as a GIF (at least
    320 px wide, ``toolkit.render.save_animation``) to ``path``."""
    from jt_tasks.standing_jump.simulate import simulate
    from toolkit.render import save_animation

    res = simulate(point, settings, record=True, record_every=1.0 / fps)
    kw = {} if settings is None else {"mass": settings.mass, "body_height": settings.height,
                                      "sim": settings.sim}
    images = render_poses([q for _, q in res.snapshots], BROWN if res.natural else BLUE, width, height, **kw)
    return save_animation(images, path, fps=fps)


def front_plot(height: np.ndarray, effort: np.ndarray, front: np.ndarray, natural: np.ndarray,
               failed: np.ndarray, path: Path, natural_max: Optional[float] = None) -> Path:
    """``004`` Fig. 8 analogue: effort objective vs jump height for every sample, front joined.

    Args:
        height: head apex height per sample ``(n,)``.
        effort: ``log(w_JE e_JE + w_SE e_SE)`` per sample ``(n,)``.
        front: non-dominated flag ``(n,)``.
        natural: no external force ``(n,)``.
        failed: failed samples ``(n,)`` (drawn as grey crosses).
        path: PNG to write.
        natural_max: highest natural jump, drawn as a dashed line.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    ok = ~failed
    if np.any(failed):
        ax.scatter(height[failed], effort[failed], marker="x", s=12, c="0.7", label="failed")
    ax.scatter(height[ok], effort[ok], facecolors="none", edgecolors="k", s=18, label="samples")
    idx = np.flatnonzero(front & ok)
    idx = idx[np.argsort(height[idx])]
    if idx.size:
        ax.plot(height[idx], effort[idx], "-", c="g", lw=1.2)
        for m, c, lab in ((natural[idx], "saddlebrown", "front, natural"),
                          (~natural[idx], "royalblue", "front, supernatural")):
            if np.any(m):
                ax.scatter(height[idx][m], effort[idx][m], c=c, s=30, zorder=3, label=lab)
    if natural_max is not None and math.isfinite(natural_max):
        ax.axvline(natural_max, ls="--", c="0.5", lw=0.8)
    ax.set_xlabel("jump height: head apex (m)")
    ax.set_ylabel("effort  log(w_JE e_JE + w_SE e_SE)")
    ax.legend(fontsize=7, loc="upper left")
    ax.set_title("Pareto front (004 Fig. 8 analogue)", fontsize=9)
    return _save(fig, path)


def _save(fig: Any, path: str | Path) -> Path:
    """Lay out, write (creating the folder) and close a matplotlib figure; returns the path."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
