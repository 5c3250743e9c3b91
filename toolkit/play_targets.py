"""What ``jt play REF`` replays: a ``Target`` resolved from a shipped skill or a trained run.

``target_of(ref)`` reads ``REF`` as a shipped skill's name, a skill folder (its ``manifest.yaml``)
or a run (``looks_like_run``). ``from_skill`` gives the environment a skill's manifest's overrides
compose, its slim policy and its env attributes. ``from_run`` takes a run id, a run's folder or its
``ppo.h5``: the environment of the run's ``config.yaml``, the attributes its checkpoint last set (as
the task's ``replay_attrs`` adjusts them from the run's metrics) and the point it was trained at
(from the run's search history or params). ``toolkit.play.replay`` replays the ``Target``.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import Any, Optional

from toolkit.errors import JtError
from toolkit.skills import Skill

_RUN_ID = re.compile(r"^[0-9a-f]{32}$")
_EVAL_DIR = re.compile(r"^eval_(\d+)$")


@dataclasses.dataclass
class Target:
    """What ``toolkit.play.replay`` replays.

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
