"""``jt play --ship RUN NAME``: make a shipped skill (``toolkit.skills``) of a trained run.

``ship(ref, name)`` writes the skill's folder: the run's slim policy, its prior, a manifest from the
run's command, tags and metrics, and the measure one replay (``toolkit.play.replay``) of that
folder reaches.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

from toolkit.errors import JtError
from toolkit.play import replay
from toolkit.play_targets import from_run, from_skill
from toolkit.skills import Skill


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
    import shutil

    from toolkit.skills import NAME, package_folder

    if not NAME.match(name):
        raise JtError(f"--ship {ref} {name}: a skill's name is letters, digits, '_', '-', '.'")
    from toolkit.store.resolve import is_path

    if is_path(ref):
        raise JtError(f"--ship {ref}: give the run's id (its command, commit and metrics come from the store)")
    target = from_run(ref, store)
    command = dict(target.run.data.tags).get("jt.command", "")
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
    fresh = not folder.exists()
    folder.mkdir(parents=True, exist_ok=True)
    try:
        return _write(target, folder, name, command, description)
    except BaseException:
        if fresh:  # nothing half-written: a new skill's folder goes again
            shutil.rmtree(folder, ignore_errors=True)
        raise


def _write(target: Any, folder: Path, name: str, command: str, description: str) -> Skill:
    """Write the skill's files from ``target`` (a run) into ``folder`` and measure it by a replay."""
    import datetime
    import shlex
    import shutil

    from toolkit.rl.checkpoint import slim
    from toolkit.skills import MANIFEST, POLICY, Skill, load_manifest, write_manifest

    run = target.run
    tags = dict(run.data.tags)
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
    keys = tuple(getattr(type(target.task), "key_metrics", ()))  # the run's own measure (e.g. every start phase)
    own = {k: round(float(metrics[k]), 4) for k in keys if k in metrics and k not in ("samples",)}
    if own:
        provenance["metrics"] = own
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
