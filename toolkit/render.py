"""Rendered frames to files: PNG filmstrips and GIF/MP4 animations; the ``Camera`` a frame is taken by.

In toolkit because simulators, tasks and the priors all render, and plugins cannot share code. The
frames come from the simulator (``Simulator.render``, ``Simulator.render_poses``).

Frames are RGB arrays ``(height, width, 3)`` uint8. The camera follows a target point and looks
at it from the side in jt's y-up world (DeepMimic convention): the character runs along +x, so the
default view is from +z.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Sequence

import numpy as np


@dataclasses.dataclass
class Camera:
    """A look-at camera.

    Attributes:
        distance: metres from the target.
        yaw: degrees around the up axis (0 looks along −z, i.e. from the +z side).
        pitch: degrees (negative looks down).
        fov: vertical field of view in degrees.
        up_axis: 1 for y-up (jt's world), 2 for z-up.
    """

    distance: float = 3.0
    yaw: float = 0.0
    pitch: float = -10.0
    fov: float = 60.0
    up_axis: int = 1


def filmstrip(frames: Sequence[np.ndarray], columns: int = 0, gap: int = 2) -> np.ndarray:
    """Frames side by side (in rows of ``columns``; 0 = one row), white gaps between them."""
    if not frames:
        raise ValueError("no frames to put in a filmstrip")
    h, w, _ = frames[0].shape
    cols = columns or len(frames)
    rows = (len(frames) + cols - 1) // cols
    strip = np.full((rows * h + (rows - 1) * gap, cols * w + (cols - 1) * gap, 3), 255, np.uint8)
    for i, f in enumerate(frames):
        r, c = divmod(i, cols)
        strip[r * (h + gap): r * (h + gap) + h, c * (w + gap): c * (w + gap) + w] = f
    return strip


def save_png(image: np.ndarray, path: str | Path) -> Path:
    """Write an RGB image as PNG."""
    import imageio.v3 as iio

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    iio.imwrite(path, image)
    return path


MIN_ANIMATION_WIDTH = 320
"""px: an animation narrower than this is enlarged (whole pixels) to at least this wide."""
SMOKE_WIDTH = 96
"""px: frames narrower than this (smoke presets render 64) are kept as they are: a smoke run checks
the pipeline, and a GIF five times its frames' size costs seconds to encode."""


def enlarge(frames: Sequence[np.ndarray], min_width: int = MIN_ANIMATION_WIDTH) -> list[np.ndarray]:
    """Frames ``(h, w, 3)`` scaled up by the smallest whole factor that makes them at least
    ``min_width`` wide (each pixel repeated: nothing blurred, nothing invented); frames already as
    wide, or narrower than ``SMOKE_WIDTH``, as they are."""
    frames = [np.asarray(f)[..., :3].astype(np.uint8) for f in frames]
    if not frames:
        return frames
    w = frames[0].shape[1]
    k = -(-int(min_width) // w) if SMOKE_WIDTH <= w < min_width else 1
    return frames if k == 1 else [np.repeat(np.repeat(f, k, axis=0), k, axis=1) for f in frames]


def save_animation(frames: Sequence[np.ndarray], path: str | Path, fps: float = 30.0,
                   min_width: int = MIN_ANIMATION_WIDTH) -> Path:
    """Write frames ``(h, w, 3)`` as an animated GIF (``.gif``) or MP4 (``.mp4``, needs
    imageio-ffmpeg), at least ``min_width`` px wide (``enlarge``; 0: as rendered)."""
    import imageio.v3 as iio

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    frames = enlarge(frames, min_width) if min_width else [np.asarray(f)[..., :3] for f in frames]
    if path.suffix == ".gif":
        iio.imwrite(path, np.stack(frames), duration=1000.0 / max(float(fps), 1e-3), loop=0)
    else:
        iio.imwrite(path, np.stack(frames), fps=fps)
    return path


_WINDOW = {"on": False}


def request_window(on: bool = True) -> None:
    """Ask the simulators created from now on, in this process, to show their world in a window
    (``jt play --gui``); a simulator that has none renders headless as always."""
    _WINDOW["on"] = bool(on)


def window_requested() -> bool:
    """Whether ``request_window`` asked for a window (a simulator reads it when it connects)."""
    return _WINDOW["on"]


def pick(frames: Sequence[Any], n: int) -> list[Any]:
    """``n`` evenly spaced items of ``frames`` (all of them if there are fewer)."""
    if len(frames) <= n:
        return list(frames)
    idx = np.linspace(0, len(frames) - 1, n).round().astype(int)
    return [frames[i] for i in idx]
