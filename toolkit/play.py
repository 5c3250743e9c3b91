"""``jt play``: replay a trained policy headless, write its animation and say what it reached.

What is replayed is a ``Target``: a shipped skill (``from_skill``: the environment its manifest's
overrides compose, its slim policy, its env attributes) or a trained run (``from_run``: a run id,
a run's folder or its ``ppo.h5``; the environment of the run's ``config.yaml``, the attributes its
checkpoint last set, as the task's ``replay_attrs`` adjusts them from the run's metrics, and the
point it was trained at, from the run's search history or params). ``replay`` builds the
environment, checks that the policy fits it, rolls the deterministic policy out once
(``toolkit.policy.episodes.rollout``, a frame per control step), writes ``<out>/<label>.gif``
(and ``.mp4`` when imageio's ffmpeg plugin is importable) and returns the task's
``play_summary``: its measure and the line ``jt play`` prints.

With ``gui`` and a display, the simulator opens PyBullet's window (``toolkit.render.request_window``)
and the replay runs at the control rate's real time.

``ship(ref, name)`` (``jt play --ship RUN NAME``) makes a shipped skill (``toolkit.skills``) of a run:
its slim policy, its prior, a manifest from the run's command, tags and metrics, and the measure one
replay of that folder reaches.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import re
import sys
import time
from pathlib import Path
from typing import Any, Optional

from toolkit.errors import JtError
from toolkit.skills import Skill

DEFAULT_OUT = "play"
"""Where ``jt play`` writes its files unless ``--out`` says: ``./play/``."""
MIN_SIZE = (320, 240)
"""px: the smallest frames ``jt play`` renders (``--width``, ``--height``)."""
_RUN_ID = re.compile(r"^[0-9a-f]{32}$")
_EVAL_DIR = re.compile(r"^eval_(\d+)$")


@dataclasses.dataclass
class Target:
    """What ``replay`` replays.

    Attributes:
        label: the output files' name (the skill's name, or ``run-<id8>``).
        task_name, task: the task and its instance (a ``PolicyTask`` built from ``cfg``).
        cfg: the run config that builds the environment.
        policy: the checkpoint (slim or full).
        point: the point the environment is built at.
        env_attrs: attributes set on the environment before the episode.
        seed: the environment's seed.
        skill: the shipped skill, or None for a run.
        run: the MLflow run, when known.
    """

    label: str
    task_name: str
    task: Any
    cfg: Any
    policy: Path
    point: dict[str, float]
    env_attrs: dict[str, Any]
    seed: int = 0
    skill: Optional[Skill] = None
    run: Any = None


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


def _policy_task(name: str, cfg: Any, what: str) -> Any:
    from toolkit import plugins

    cls = plugins.load("task", name)
    if not callable(getattr(cls, "play_summary", None)):
        raise JtError(f"{what}: task={name} trains no policy; jt play replays policy tasks")
    return cls(cfg)


def from_skill(skill: Skill) -> Target:
    """The replay of a shipped skill (its overrides composed, its task built)."""
    from toolkit.config import compose_skill

    cfg = compose_skill(skill)
    task = _policy_task(skill.task, cfg, f"skill '{skill.name}'")
    return Target(label=skill.name, task_name=skill.task, task=task, cfg=cfg, policy=skill.policy,
                  point=dict(skill.point), env_attrs=dict(skill.env_attrs), seed=int(skill.seed), skill=skill)


def looks_like_run(ref: str) -> bool:
    """Whether ``ref`` names a run (an MLflow run id) or a path rather than a skill name."""
    from toolkit.store.resolve import is_path

    return bool(_RUN_ID.match(ref)) or is_path(ref)


def from_run(ref: str, store: Optional[str] = None) -> Target:
    """The replay of a trained run: ``ref`` is its id, its folder or its ``ppo.h5``.

    Raises:
        JtError: one line: nothing trained there, no config beside it, a task with no policy.
    """
    from omegaconf import OmegaConf

    from toolkit.config import validate
    from toolkit.rl.checkpoint import load_attrs
    from toolkit.store.resolve import resolve

    try:
        found = resolve(ref, artifact="ppo.h5", store=store, what="run", label="trained policy",
                        hint="jt play lists the shipped skills")
    except JtError as e:  # "run=REF: ..." as "jt play REF: ..."
        raise JtError(f"jt play {str(e)[len('run='):]}") from None
    path = found.path
    try:
        load_attrs(path)
    except (OSError, ValueError, KeyError) as e:
        raise JtError(f"jt play {ref}: {path} is not a jt PPO checkpoint ({str(e).splitlines()[0][:160]})") from None
    run = found.run if found.run is not None else _run_of_file(path)
    cfg_path = _config_of(path, run, store)
    try:
        cfg = validate(OmegaConf.load(cfg_path), (), False)
    except JtError as e:
        raise JtError(f"jt play {ref}: its config {cfg_path} no longer composes: {e}") from None
    name = str(cfg.task.name)
    task = _policy_task(name, cfg, f"jt play {ref}")
    point, metrics = _trained_at(path, run)
    env_attrs = task.replay_attrs(_env_attrs(path), metrics)
    seed = int(cfg.get("seed", 0) or 0)
    return Target(label=_label(path, run, name), task_name=name, task=task,
                  cfg=cfg, policy=path, point=point, env_attrs=env_attrs, seed=seed, run=run)


def _label(path: Path, run: Any, task: str) -> str:
    """The output files' name for a run's checkpoint: ``run-<id8>`` (``-eval_NNNN`` for an
    evaluation's work folder), else ``<task>-<folder>``."""
    rid = run.info.run_id if run is not None else \
        next((p.name for p in path.parents[:3] if _RUN_ID.match(p.name)), "")
    if not rid:
        return f"{task}-{path.parent.name}"
    return f"run-{rid[:8]}" + (f"-{path.parent.name}" if _EVAL_DIR.match(path.parent.name) else "")


def _env_attrs(path: Path) -> dict[str, Any]:
    """A checkpoint's ``env_attrs`` group (without reading the rest of the file)."""
    import h5py

    from toolkit.rl.checkpoint import read_tree

    with h5py.File(path, "r") as f:
        return dict(read_tree(f["env_attrs"])) if "env_attrs" in f else {}


def _run_of_file(path: Path) -> Any:
    """The MLflow run whose artifact ``path`` is (``<store>/runs/<task>/<id>/artifacts/``), or None."""
    folder = path.parent
    if folder.name != "artifacts" or not _RUN_ID.match(folder.parent.name) or len(path.parents) < 5:
        return None
    root = path.parents[4]
    if not (root / "mlflow.db").is_file():
        return None
    try:
        from toolkit.store.resolve import open_store

        return open_store(str(root)).client.get_run(folder.parent.name)
    except Exception:  # noqa: BLE001 - an unreadable store only loses the run's metrics
        return None


def _config_of(path: Path, run: Any, store: Optional[str]) -> Path:
    """The ``config.yaml`` of the run that wrote ``path``: beside it or one folder up, else in
    the artifacts of its outer run (a nested evaluation's)."""
    for folder in (path.parent, path.parent.parent):
        if (folder / "config.yaml").is_file():
            return folder / "config.yaml"
    parent = run.data.tags.get("mlflow.parentRunId") if run is not None else None
    if parent:
        from toolkit.store.resolve import open_store

        st = open_store(store)
        cand = st.artifact_dir(parent) / "config.yaml" if st is not None else None
        if cand is not None and cand.is_file():
            return cand
    raise JtError(f"jt play: no config.yaml beside {path} (a run's artifacts or work folder holds one)")


def _trained_at(path: Path, run: Any) -> tuple[dict[str, float], dict[str, float]]:
    """``(point, metrics)`` of the evaluation that trained ``path``: its row of the search
    history beside it (or one folder up, ``eval_NNNN``'s), else the run's params and metrics."""
    import numpy as np

    from toolkit.store import h5

    for folder, file in ((path.parent, "search_history.h5"), (path.parent.parent, "search_history.h5")):
        if not (folder / file).is_file():
            continue
        try:
            hist = h5.read(folder / file)
            names = [n.decode() if isinstance(n, bytes) else str(n) for n in np.asarray(hist["names"]).ravel()]
            index = list(np.asarray(hist["index"]).ravel().astype(int))
        except (OSError, KeyError, ValueError):
            continue
        m = _EVAL_DIR.match(path.parent.name)
        row = index.index(int(m.group(1))) if m and int(m.group(1)) in index else (0 if len(index) == 1 else None)
        if row is None:
            continue
        x = np.asarray(hist["x"], dtype=float)[row]
        metrics = {k: float(np.asarray(v).ravel()[row]) for k, v in (hist.get("metrics") or {}).items()}
        return dict(zip(names, map(float, x))), metrics
    if run is None:
        return {}, {}
    point = {}
    if "mlflow.parentRunId" in run.data.tags:  # a nested evaluation: its params are its point and seed
        for k, v in run.data.params.items():
            try:
                point[k] = float(v)
            except ValueError:
                continue
        point.pop("seed", None)
    return point, dict(run.data.metrics)


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


def target_of(ref: str, store: Optional[str] = None) -> Target:
    """The ``Target`` ``jt play REF`` names: a shipped skill's name, a skill folder (its
    ``manifest.yaml``), or a run (``from_run``); an unknown name is one line naming the skills."""
    from toolkit import skills

    ref = str(ref).strip()
    if (Path(ref).expanduser() / skills.MANIFEST).is_file():
        return from_skill(skills.load_manifest(ref))
    if ref in skills.names():
        return from_skill(skills.find(ref))
    if looks_like_run(ref):
        return from_run(ref, store)
    skills.find(ref)  # raises: the shipped names
    raise AssertionError  # pragma: no cover


def ship(ref: str, name: str, store: Optional[str] = None, into: Optional[Any] = None,
         description: str = "") -> Skill:
    """Make (or remake) the skill ``name`` from the trained run ``ref`` (a run id: its command,
    commit and metrics come from the store) and return it, measured by one replay.

    Args:
        ref: the run id (an outer ``search=single`` run, or a nested evaluation).
        name: the skill's name (its folder's).
        store: the store (``store_root`` rules).
        into: the folder that gets ``<name>/``; None: the task's skills package.
        description: the manifest's one line; "" keeps the one already there, else names the run.
    """
    import datetime
    import shlex
    import shutil

    from toolkit.rl.checkpoint import slim
    from toolkit.skills import MANIFEST, NAME, POLICY, Skill, load_manifest, package_folder, write_manifest

    if not NAME.match(name):
        raise JtError(f"--ship {ref} {name}: a skill's name is letters, digits, '_', '-', '.'")
    from toolkit.store.resolve import is_path

    if is_path(ref):
        raise JtError(f"--ship {ref}: give the run's id (its command, commit and metrics come from the store)")
    target = from_run(ref, store)
    run = target.run
    tags = dict(run.data.tags)
    command = tags.get("jt.command", "")
    if not command:
        raise JtError(f"--ship {ref}: the run has no jt.command tag (its overrides are unknown)")
    if into is None:
        pkg = str(getattr(type(target.task), "skills", "") or "")
        base = package_folder(pkg) if pkg else None
        if base is None:
            raise JtError(f"--ship {ref}: task={target.task_name} declares no skills package (Task.skills); give --out")
    else:
        base = Path(into).expanduser()
    folder = (base / name).resolve()
    folder.mkdir(parents=True, exist_ok=True)
    old = folder / MANIFEST
    kept = load_manifest(folder).description if old.is_file() and (folder / POLICY).is_file() else ""
    overrides = [o for o in shlex.split(command)[2:] if not o.startswith(("store=", "resume="))]
    command = " ".join(["jt", "run", *map(shlex.quote, overrides)])  # to retrain it (in any store)
    prior = _prior_file(target.cfg)
    if prior is not None:
        if prior.resolve() != (folder / "prior.h5").resolve():  # a skill remade from its own replay's run
            shutil.copyfile(prior, folder / "prior.h5")
        overrides = [o for o in overrides if not o.startswith("action.prior=")] + ["action.prior=prior.h5"]
    slim(target.policy, folder / POLICY)
    metrics = dict(run.data.metrics)
    start = getattr(run.info, "start_time", None)
    date = datetime.datetime.fromtimestamp(start / 1000, datetime.timezone.utc).strftime("%Y-%m-%d") if start else ""
    provenance = {"command": command, "run_id": run.info.run_id, "commit": tags.get("jt.git_commit", ""),
                  "samples": int(metrics.get("samples", -1)),
                  "train_wall_s": round(float(metrics.get("train_wall_s", float("nan"))), 1), "date": date}
    skill = Skill(name=name, task=target.task_name, folder=folder, overrides=overrides, point=target.point,
                  env_attrs=target.env_attrs, seed=int(target.seed),
                  description=description or kept or f"task={target.task_name} trained by run {run.info.run_id}",
                  provenance=provenance)
    write_manifest(skill)  # measured next, by a replay of what was just written
    played = replay(from_skill(load_manifest(folder)), None)
    skill.measure = played.measure
    write_manifest(skill)
    return skill


def _prior_file(cfg: Any) -> Optional[Path]:
    """The prior file the run's action space decoded through (``action.prior``), or None."""
    from toolkit.config import group_of

    action = group_of(cfg, "action")
    ref = str(group_of(action, "prior") or "").strip() if action is not None else ""
    if not ref:
        return None
    from toolkit.store.resolve import resolve

    store = str(group_of(action, "store") or "").strip() or group_of(cfg, "store")
    return resolve(ref, artifact="prior.h5", store=None if store is None else str(store), what="action.prior",
                   label="pose prior").path
