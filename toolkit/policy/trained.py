"""A policy trained earlier, measured instead of trained: ``task.evaluate=NAME|RUN|PATH``.

``PolicyConfig.evaluate`` names a trained policy: a shipped skill's name (``toolkit.skills``), a
run id (its best evaluation), a folder or a ``ppo.h5``. ``trained_skill`` / ``trained_policy``
resolve it (one ``JtError`` line when it names nothing, or a slim policy by path);
``check_policy_fits`` checks, before a run opens, that the policy's observation and action sizes
are those of the task's environment as configured, and ``check_skill_settings`` that a skill's
environment is the run's. ``PolicyTask.evaluate`` then takes the policy into the evaluation's
folder instead of training one: ``adopt_checkpoint`` (a run's full checkpoint, resumed with no
sample left to collect) or ``adopt_skill`` (a skill's slim policy).

``PolicyConfig.warm_start`` names a trained run's full checkpoint that training starts from
(``warm_policy``: its networks and normaliser, fresh optimiser and counters; checked the same way).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Callable, Optional

from toolkit.config import group_of

from toolkit.policy import train as tr
from toolkit.policy.episodes import opened_env


def check_policy_fits(cfg: Any, task: str, path: Path, key: str = "evaluate") -> None:
    """``task.<key>``'s policy (``evaluate``, ``warm_start``) takes the observation and gives the
    action of ``task``'s environment as configured (sizes from the checkpoint, against an
    environment built here): a run of another task, or of other settings, is one ``JtError``
    line before a run opens."""
    from toolkit import plugins
    from toolkit.errors import JtError
    from toolkit.rl.checkpoint import load_attrs

    skill = trained_skill(cfg, task) if key == "evaluate" else None
    if skill is not None:
        check_skill_settings(cfg, task, skill)
    attrs = load_attrs(path)
    want = (int(attrs["obs_dim"]), int(attrs["act_dim"]))
    with opened_env(plugins.load("task", task)(cfg).make_env, seed=0) as env:
        have = (int(env.observation_space.shape[0]), int(env.action_space.shape[0]))
    if want != have:
        ref = str(group_of(group_of(cfg, "task"), key)).strip()
        raise JtError(f"task.{key}={ref}: its policy takes {want[0]} observations and gives {want[1]} actions; "
                      f"task={task} as configured here observes {have[0]} and acts with {have[1]} "
                      f"(a run of another task, or of other task/action settings)")


def trained_policy(cfg: Any, task: str) -> Optional[Path]:
    """The ``ppo.h5`` that ``task.evaluate`` names (a run id, a folder or the file), or None when
    it is unset; one ``JtError`` line when it names nothing."""
    ref = str(group_of(group_of(cfg, "task") or {}, "evaluate") or "").strip()
    if not ref:
        return None
    skill = trained_skill(cfg, task)
    if skill is not None:
        return skill.policy
    from toolkit.store.resolve import resolve

    from toolkit.errors import JtError
    from toolkit.rl.checkpoint import load_attrs

    store = group_of(cfg, "store")
    path = resolve(ref, artifact=tr.CHECKPOINT, store=None if store is None else str(store),
                   what="task.evaluate", label="trained policy", hint=f"train one with: jt run task={task}").path
    try:  # read now, before a run opens: a file that is no PPO checkpoint is one line
        attrs = load_attrs(path)
    except (OSError, ValueError, KeyError) as e:
        raise JtError(f"task.evaluate={ref}: {path} is not a jt PPO checkpoint "
                      f"({str(e).splitlines()[0][:160]}); train one with: jt run task={task}") from None
    if attrs.get("slim"):  # a shipped skill's policy: no training state to resume from
        raise JtError(f"task.evaluate={ref}: {path} is a slim policy (a shipped skill's: no value network or "
                      f"training state); measure a shipped skill by its name (task.evaluate=NAME, jt play lists "
                      f"them) or replay it with: jt play {ref}")
    return path


def warm_policy(cfg: Any, task: str) -> Optional[Path]:
    """The full ``ppo.h5`` that ``task.warm_start`` names (a run id, a folder or the file), or None
    when it is unset; one ``JtError`` line when it names nothing, a file that is no PPO checkpoint,
    a slim policy (no value network), or comes with ``task.evaluate``."""
    group = group_of(cfg, "task") or {}
    ref = str(group_of(group, "warm_start") or "").strip()
    if not ref:
        return None
    from toolkit.errors import JtError

    if str(group_of(group, "evaluate") or "").strip():
        raise JtError(f"task.warm_start={ref}: task.evaluate measures a trained policy without training; "
                      "give one of the two")
    from toolkit.rl.checkpoint import load_attrs
    from toolkit.store.resolve import resolve

    store = group_of(cfg, "store")
    path = resolve(ref, artifact=tr.CHECKPOINT, store=None if store is None else str(store),
                   what="task.warm_start", label="trained policy", hint=f"train one with: jt run task={task}").path
    try:
        attrs = load_attrs(path)
    except (OSError, ValueError, KeyError) as e:
        raise JtError(f"task.warm_start={ref}: {path} is not a jt PPO checkpoint ({str(e).splitlines()[0][:160]})") from None
    if attrs.get("slim"):
        raise JtError(f"task.warm_start={ref}: {path} is a slim policy (a shipped skill's: no value network); "
                      "start from a trained run's ppo.h5")
    return path


def trained_skill(cfg: Any, task: str = "") -> Any:
    """The shipped skill (``toolkit.skills.Skill``) that ``task.evaluate`` names, or None when it
    names a run, a folder, a file or nothing; one ``JtError`` line, naming the shipped skills, for
    a name that is none of them."""
    from toolkit import skills

    ref = str(group_of(group_of(cfg, "task") or {}, "evaluate") or "").strip()
    if not skills.is_skill_ref(ref):
        return None
    found, _ = skills.scan()
    for skill in found:
        if skill.name == ref:
            return skill
    from toolkit.errors import JtError

    shipped = ", ".join(s.name for s in found) or "(none)"
    train = f"; train one with: jt run task={task}" if task else ""
    raise JtError(f"task.evaluate={ref}: no shipped skill of that name (shipped: {shipped}; jt play lists them), "
                  f"and not a run id or a path{train}")


def _plain(value: Any) -> Any:
    """``value`` with arrays, numpy scalars, tuples and dataclasses made plain lists, numbers, dicts."""
    import numpy as np

    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        value = {f.name: getattr(value, f.name) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (np.ndarray, list, tuple)):
        return [_plain(v) for v in (value.tolist() if isinstance(value, np.ndarray) else value)]
    return value.item() if isinstance(value, np.generic) else value


def _flat(value: Any, prefix: str = "") -> dict[str, Any]:
    """An env spec as ``{dotted key: plain value}`` (nested dataclasses and dicts spelled out)."""
    value = _plain(value)
    if isinstance(value, dict) and value:
        out: dict[str, Any] = {}
        for k, v in value.items():
            out.update(_flat(v, f"{prefix}{k}."))
        return out
    return {prefix.rstrip("."): value}


def check_skill_settings(cfg: Any, task: str, skill: Any) -> None:
    """``task.evaluate=NAME``: the run's environment is the shipped skill's, the one its policy was
    trained in (``env_spec`` at the skill's point, from this run's config and from the skill's
    overrides); else one ``JtError`` line naming the first settings that differ."""
    from toolkit import plugins
    from toolkit.errors import JtError

    if skill.task != task:
        raise JtError(f"task.evaluate={skill.name}: a skill of task={skill.task}, this run is task={task}; "
                      f"leave task= out (jt run task.evaluate={skill.name} composes the skill's own settings)")
    from toolkit.config import compose_skill

    cls = plugins.load("task", task)
    store = group_of(cfg, "store")  # what the store and task.evaluate put in a spec is the run's on both sides
    own = compose_skill(skill, *([f"store={store}"] if store else []), f"task.evaluate={skill.name}", run_checks=False)
    mine = _flat(cls(cfg).env_spec(dict(skill.point)))
    theirs = _flat(cls(own).env_spec(dict(skill.point)))
    diff = [k for k in list(theirs) + [k for k in mine if k not in theirs] if mine.get(k) != theirs.get(k)]
    if diff:
        shown = ", ".join(f"{k}={mine.get(k)!r} (the skill's {theirs.get(k)!r})" for k in diff[:3])
        more = f" and {len(diff) - 3} more" if len(diff) > 3 else ""
        raise JtError(f"task.evaluate={skill.name}: this run's environment is not the skill's (its env spec: "
                      f"{shown}{more}); "
                      f"leave out the overrides that change it (jt run task.evaluate={skill.name} composes the "
                      f"skill's own: {' '.join(skill.overrides)})")


def adopt_checkpoint(cfg: Any, task: str, workdir: Path) -> Optional[Callable[[Any], Any]]:
    """With ``task.evaluate``: copy its checkpoint into ``workdir`` (where training resumes from)
    and return the ``PPOConfig`` change that makes its sample count the budget, so PPO resumes
    with nothing left to collect; None without it."""
    import shutil

    from toolkit.rl.checkpoint import load, with_architecture

    src = trained_policy(cfg, task)
    if src is None:
        return None
    dst = Path(workdir) / tr.CHECKPOINT
    if not dst.exists():  # copied whole, then renamed: a kill never leaves half a checkpoint
        from toolkit.store.atomic import atomic_write

        with atomic_write(dst) as tmp:
            shutil.copyfile(src, tmp)
    done = int(load(dst)[0]["counters"]["samples"])
    return lambda c: dataclasses.replace(with_architecture(c, dst), total_samples=done)


def adopt_skill(skill: Any, workdir: Path) -> Path:
    """A shipped skill's slim policy copied into ``workdir`` as its ``ppo.h5`` (logged with the
    run, as a trained run's is; ``jt play RUN`` replays it)."""
    import shutil

    dst = Path(workdir) / tr.CHECKPOINT
    if not dst.exists():
        from toolkit.store.atomic import atomic_write

        with atomic_write(dst) as tmp:
            shutil.copyfile(skill.policy, tmp)
    return dst
