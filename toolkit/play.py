"""``jt play``: replay a trained policy headless, write its animation and say what it reached.

``replay`` takes a ``toolkit.play_targets.Target`` (a shipped skill or a trained run), builds its
environment, checks that the policy fits it, rolls the deterministic policy out once
(``toolkit.policy.episodes.rollout``, a frame per control step), writes ``<out>/<label>.gif``
(and ``.mp4`` when imageio's ffmpeg plugin is importable) and returns the task's
``play_summary``: its measure and the line ``jt play`` prints.

With ``gui`` and a display, the simulator opens PyBullet's window (``toolkit.render.request_window``)
and the replay runs at the control rate's real time.

What to replay is resolved in ``toolkit.play_targets``; ``toolkit.ship`` (``jt play --ship``)
makes a shipped skill of a run.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import sys
import time
from pathlib import Path
from typing import Any, Optional

from toolkit.errors import JtError
from toolkit.play_targets import Target

DEFAULT_OUT = "play"
"""Where ``jt play`` writes its files unless ``--out`` says: ``./play/``."""
MIN_SIZE = (320, 240)
"""px: the smallest frames ``jt play`` renders (``--width``, ``--height``)."""


@dataclasses.dataclass
class Played:
    """What ``replay`` did: the task's ``measure`` and ``line``, the files written, the frames'
    count and size, the wall time, whether ``seconds`` cut the episode, and notes to print."""

    measure: dict[str, Any]
    line: str
    files: list[Path]
    frames: int
    size: tuple[int, int]
    wall_s: float
    capped: bool
    notes: list[str]


def display() -> str:
    """Why no window can open here ("" when one can): no ``DISPLAY`` / ``WAYLAND_DISPLAY`` on
    Linux and the BSDs (macOS and Windows always have one)."""
    if sys.platform.startswith(("darwin", "win", "cygwin")):
        return ""
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return ""
    return "no display here (DISPLAY is unset)"


def check_options(width: int, height: int, seconds: Optional[float] = None) -> None:
    """Frames of at least ``MIN_SIZE`` and a cap > 0 s; one ``JtError`` line otherwise."""
    if int(width) < MIN_SIZE[0] or int(height) < MIN_SIZE[1]:
        raise JtError(f"--width {width} --height {height}: jt play renders at least {MIN_SIZE[0]}x{MIN_SIZE[1]} px")
    if seconds is not None and not (math.isfinite(float(seconds)) and float(seconds) > 0):
        raise JtError(f"--seconds {seconds}: must be a number of seconds > 0")


def mp4_writer() -> bool:
    """Whether imageio's ffmpeg plugin is importable (an MP4 is written beside the GIF)."""
    import importlib.util

    return importlib.util.find_spec("imageio_ffmpeg") is not None


def replay(target: Target, out: Optional[Any] = DEFAULT_OUT, seconds: Optional[float] = None,
           seed: Optional[int] = None, start: Optional[str] = None, gui: bool = False,
           width: int = MIN_SIZE[0], height: int = MIN_SIZE[1]) -> Played:
    """Roll ``target``'s policy out once and write its animation.

    Args:
        target: what to replay (``from_skill``, ``from_run``).
        out: the folder for ``<label>.gif`` / ``.mp4`` (created); None: no files (a measure only).
        seconds: end the episode after this many simulated seconds (None: when it ends).
        seed: the environment's seed (None: the target's).
        start: ``--start``, for the task's ``play_options``.
        gui: show PyBullet's window, paced at real time, when a display exists.
        width, height: frame size (px), at least ``MIN_SIZE``.

    Returns:
        ``Played``.
    """
    from toolkit.policy.episodes import rollout
    from toolkit.quiet import native_stderr_silenced
    from toolkit.render import request_window, save_animation
    from toolkit.rl.checkpoint import load_policy
    from toolkit.skills import check_fits, differences, measure_text

    t0 = time.perf_counter()
    check_options(width, height, seconds)
    folder = None
    if out is not None:
        from toolkit.study import writable_folder

        folder = writable_folder(out, "--out")
    notes: list[str] = []
    window = False
    if gui:
        why = display()
        window = not why
        if why:
            notes.append(f"--gui: {why}; replayed headless")
    task = target.task
    model = load_policy(target.policy)
    request_window(window)
    quiet = native_stderr_silenced if window else contextlib.nullcontext  # the window's C-level chatter
    try:
        with quiet():
            env = task.make_env(dict(target.point), seed=target.seed if seed is None else int(seed))
        try:
            check_fits(target.policy, env, target.skill, f"jt play {target.label}")
            for key, value in target.env_attrs.items():
                setattr(env, key, value)
            options = task.play_options(env, start)
            hz = float(env.control_hz)
            cap = None if seconds is None else max(1, int(round(float(seconds) * hz)))
            record = _paced(task.record, hz) if window else task.record
            ro = rollout(env, model, record, 1, int(width), int(height), options, max_steps=cap)
            measure, line = task.play_summary(env, ro)
            capped = cap is not None and not getattr(env, "done", True)
            if window and sys.stdin.isatty():
                input("jt play: press Enter to close the window ")
        finally:
            with quiet():
                env.close()
    finally:
        request_window(False)
    if capped:
        line += f" [cut at --seconds {seconds}]"
    files: list[Path] = []
    if folder is not None and ro.frames:
        files.append(save_animation(ro.frames, folder / f"{target.label}.gif", hz))
        if mp4_writer():
            files.append(save_animation(ro.frames, folder / f"{target.label}.mp4", hz))
        else:
            notes.append("no MP4: imageio's ffmpeg plugin is not installed (pip install imageio-ffmpeg)")
    if target.skill is not None and target.skill.measure and not capped and start is None and seed is None:
        diff = differences(measure, target.skill.measure)
        if diff:
            notes.append(f"differs from the documented measure ({measure_text(target.skill.measure)}): {', '.join(diff)}")
    h, w = ro.frames[0].shape[:2] if ro.frames else (0, 0)
    if files:  # the written size (save_animation enlarges narrow frames)
        import imageio.v3 as iio

        h, w = iio.improps(files[0], index=0).shape[:2]
    return Played(measure=measure, line=line, files=files, frames=len(ro.frames), size=(int(w), int(h)),
                  wall_s=time.perf_counter() - t0, capped=capped, notes=notes)


def _paced(record: Any, hz: float) -> Any:
    """``record`` that first waits out the control step's real time (the window's replay speed)."""
    state = {"t": time.perf_counter()}

    def paced(env: Any) -> Any:
        wait = state["t"] + 1.0 / hz - time.perf_counter()
        if wait > 0:
            time.sleep(wait)
        state["t"] = time.perf_counter()
        return record(env)

    return paced
