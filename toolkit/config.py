"""Compose a run's config with Hydra (``conf/`` + config shipped by installed plugins), and check it.

Checks, each failing as one ``JtError`` line: override syntax; every plugin choice against the
registry (``jt: unknown search 'bdx'; choose one of: bds, random, ...``); every other group choice
against the YAML files on the search path; each plugin's group against the plugin's ``Config``
dataclass (unknown key, wrong type); the top-level keys against ``RunConfig``.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Optional, Sequence

from toolkit import plugins
from toolkit.errors import JtError
from toolkit.schema import RunConfig, config_of, validate  # noqa: F401 - re-exported


def conf_dir() -> Path:
    """The built-in ``conf/`` directory (source checkout or installed copy)."""
    here = Path(__file__).resolve().parent
    for cand in (here.parent / "conf", here / "_conf"):
        if (cand / "config.yaml").is_file():
            return cand
    raise JtError(f"jt's conf/ directory is missing (looked in {here.parent / 'conf'})")


def _search_path() -> list[str]:
    return [f"pkg://{pkg}" for _, pkg in plugins.config_packages()]


def _group_dirs() -> list[Path]:
    """Config roots: built-in conf/ then each plugin package's config package."""
    roots = [conf_dir()]
    import importlib.util

    for _, pkg in plugins.config_packages():
        try:
            spec = importlib.util.find_spec(pkg)
        except (ImportError, ValueError):
            spec = None
        if spec is not None and spec.submodule_search_locations:
            roots.extend(Path(p) for p in spec.submodule_search_locations)
    return roots


def group_options(group: str) -> list[str]:
    """YAML options of a config group across all config roots."""
    out = set()
    for root in _group_dirs():
        d = root / group
        if d.is_dir():
            out.update(p.stem for p in d.glob("*.yaml"))
    return sorted(out)


def _parse(overrides: Sequence[str]) -> list[Any]:
    from hydra.core.override_parser.overrides_parser import OverridesParser

    parser = OverridesParser.create()
    parsed = []
    for o in overrides:
        key, eq, value = o.partition("=")
        if eq and not key.strip().lstrip("+~"):
            raise JtError(f"bad override '{o}': no key before '='; write KEY=VALUE (e.g. task.clip=walk)")
        try:
            parsed.extend(parser.parse_overrides([o]))
        except Exception as e:  # noqa: BLE001 - Hydra raises several types here
            if eq and not value.isascii() and value[:1] not in "'\"":
                raise JtError(f"bad override '{o}': a value with characters beyond ASCII letters, digits and "
                              f"_-./ must be quoted: {key}='{value}' (on a shell command line: \"{key}='{value}'\")") \
                    from None
            msg = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
            raise JtError(f"bad override '{o}': {msg}") from e
    return parsed


def _check_choices(parsed: Sequence[Any]) -> None:
    for ov in parsed:
        key = ov.key_or_group
        if "." in key or "/" in key or ov.is_delete() or ov.package:
            continue
        value = ov.value()
        if not isinstance(value, str):
            continue
        if key in plugins.KINDS:
            # a kind's group holds plugin configs (name: <plugin>) and may hold other option
            # files (e.g. reward/highjump.yaml, a set of terms); the validator checks `name:` later
            options = group_options(key)
            if value not in options:
                choices = sorted(set(options) | set(plugins.names(key)))
                raise plugins.UnknownPlugin(key, value, choices)
        else:
            opts = group_options(key)
            if opts and value not in opts:
                raise JtError(f"unknown {key} '{value}'; choose one of: {', '.join(opts)}")


def _one_line(e: BaseException) -> str:
    text = str(e).strip()
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    if not lines:
        return type(e).__name__
    key = getattr(e, "full_key", None)
    if key and "Value '" in lines[0]:
        return f"{key}: {lines[0]}"
    if lines[0].startswith("Could not override '"):
        key = lines[0].split("'")[1]
        group = key.split(".")[0]
        hint = ""
        if group in plugins.KINDS:
            hint = f" (see the keys with: jt run --cfg {group}=...)"
        return f"unknown key '{key}'{hint}"
    if lines[0].startswith("You must specify '"):
        group = lines[0].split("'")[1]
        opts = group_options(group)
        return f"choose a {group}: {group}=<one of: {', '.join(opts)}>" if opts else lines[0]
    return lines[0]


def _defer(ov: Any) -> bool:
    """A ``group.key=value`` assignment applied on the typed group after composition (so that the
    key is checked against the group's schema, not against what its YAML happens to list)."""
    from hydra.core.override_parser.types import OverrideType

    key = ov.key_or_group
    if "." not in key or "/" in key or ov.package or ov.is_sweep_override():
        return False
    return ov.type in (OverrideType.CHANGE, OverrideType.ADD, OverrideType.FORCE_ADD)


def _choice(parsed: Sequence[Any], group: str) -> Optional[str]:
    """The ``group=...`` choice on the command line, else the primary config's default."""
    for ov in reversed(list(parsed)):
        if ov.key_or_group == group and not ov.is_delete() and isinstance(ov.value(), str):
            return str(ov.value())
    from omegaconf import OmegaConf

    for entry in OmegaConf.load(conf_dir() / "config.yaml").get("defaults", []):
        if OmegaConf.is_dict(entry) and group in entry:
            return None if entry[group] is None else str(entry[group])
    return None


def _preset(parsed: Sequence[Any]) -> list[str]:
    """``preset=<experiment>_<task>`` when such a preset exists (it may choose groups itself).

    Raises:
        JtError: an ``experiment=`` other than ``default`` that the task has no preset for (it
            would silently run the task's defaults), naming the experiments the task has.
    """
    if _choice(parsed, "preset") is not None:
        return []
    experiment, task = _choice(parsed, "experiment") or "default", _choice(parsed, "task")
    presets = group_options("preset")
    name = f"{experiment}_{task}"
    if name in presets:
        return [f"preset={name}"]
    if experiment != "default" and task is not None:
        known = sorted({p[: -len(task) - 1] for p in presets if p.endswith(f"_{task}")} | {"default"})
        known = [e for e in known if e in group_options("experiment")]
        raise JtError(f"experiment={experiment}: task={task} has no preset for it (preset/{name}.yaml), so it would "
                      f"run the task's defaults; its experiments: {', '.join(known)}")
    return []


def compose(overrides: Sequence[str] = (), run_checks: bool = True) -> Any:
    """Compose ``conf/config.yaml`` with ``overrides`` (Hydra syntax), checked and typed.

    ``task.evaluate=NAME`` of a shipped skill puts the skill's own overrides under these
    (``toolkit.skills.evaluate_overrides``); an error then says which of these replaced the skill's.

    Hydra composes the defaults lists: the task's own group choices (``override /spd: df`` in
    ``conf/task/<task>.yaml``), then the experiment's per-task preset ``preset/<experiment>_<task>``
    (which may choose groups too), then the command line, which wins. ``group.key=value``
    assignments are applied afterwards on the group typed by its schema (``toolkit.schema``).

    Args:
        overrides: Hydra overrides.
        run_checks: also run the chosen plugins' cross-group checks (``Plugin.check_run``); off
            for ``jt run --cfg``, which prints a config that cannot run yet and says why.

    Returns:
        An OmegaConf ``DictConfig``; every group typed by its schema, struct.

    Raises:
        JtError: one line naming what is wrong and, for choices, the valid ones.
    """
    from toolkit.skills import evaluate_overrides, replaced_overrides

    given = list(overrides)
    overrides = evaluate_overrides(given)  # task.evaluate=NAME: a shipped skill's own settings under these
    if len(overrides) == len(given):
        return _compose(given, run_checks)
    try:
        return _compose(overrides, run_checks)
    except JtError as e:
        clash = replaced_overrides(given)
        if not clash or str(e).startswith("task.evaluate="):  # a line of its own about the skill
            raise
        raise JtError(f"{e} (task.evaluate composes the skill's settings under yours: {clash}; leave those out)") from e


def compose_skill(skill: Any, *more: str, run_checks: bool = True) -> Any:
    """The run config a shipped skill's overrides compose (``toolkit.skills.Skill``: its
    environment's settings), with ``more`` overrides after them; one ``JtError`` line when they
    compose another task than its manifest says."""
    cfg = compose([*skill.resolved_overrides(), *more], run_checks)
    got = str(cfg.task.name)
    if got != skill.task:
        raise JtError(f"skill '{skill.name}': its overrides compose task={got}, its manifest says task={skill.task}")
    return cfg


def _compose(overrides: list[str], run_checks: bool) -> Any:
    """``compose`` of the overrides as they are."""
    from hydra import compose as hydra_compose
    from hydra import initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra

    from toolkit.schema import ignored_choice, validate

    parsed = _parse(overrides)
    _check_choices(parsed)
    task = _choice(parsed, "task")
    for ov in parsed:  # a group with a default that the task never reads (the optional ones: run_checks)
        if task is not None and not ov.is_delete() and not ov.package:
            ignored_choice(task, ov.key_or_group, ov.value())
    hydra_overrides, deferred = [], []
    for text, ov in zip(overrides, parsed):
        if _defer(ov):
            deferred.append((ov.key_or_group, ov.value()))
        else:
            hydra_overrides.append(text)
    hydra_overrides += _preset(parsed)
    extra = _search_path()
    if extra:
        hydra_overrides.append("hydra.searchpath=[" + ",".join(extra) + "]")
    GlobalHydra.instance().clear()
    try:
        with initialize_config_dir(config_dir=str(conf_dir()), version_base=None):
            cfg = hydra_compose("config", overrides=hydra_overrides)
    except JtError:
        raise
    except Exception as e:  # noqa: BLE001 - Hydra/OmegaConf raise many types; one line each
        raise JtError(f"config: {_one_line(e)}") from e
    finally:
        GlobalHydra.instance().clear()
    return validate(cfg, deferred, run_checks)


def to_yaml(cfg: Any) -> str:
    """The composed config as YAML (resolved)."""
    from omegaconf import OmegaConf

    return OmegaConf.to_yaml(cfg, resolve=True)


def flatten(cfg: Any) -> dict[str, str]:
    """Dotted ``{key: value}`` of a config, for MLflow params."""
    from omegaconf import OmegaConf

    out: dict[str, str] = {}

    def walk(prefix: str, node: Any) -> None:
        if isinstance(node, dict):
            for k, v in node.items():
                walk(f"{prefix}.{k}" if prefix else str(k), v)
        else:
            out[prefix] = str(node)

    walk("", OmegaConf.to_container(cfg, resolve=True))
    return out


def group_of(cfg: Any, key: str) -> Any:
    """The ``key`` group of a run config (DictConfig, dict or attribute object); None if absent."""
    if cfg is None:
        return None
    try:
        return cfg[key] if key in cfg else None
    except TypeError:
        return getattr(cfg, key, None)


def plain(node: Any) -> dict:
    """A config node as a plain, resolved ``dict`` (``{}`` for None) — picklable for workers."""
    from omegaconf import OmegaConf

    return OmegaConf.to_container(node, resolve=True) if OmegaConf.is_config(node) else dict(node or {})


def task_params(config_cls: type, cfg: Any) -> Any:
    """A task's typed ``Config`` from the whole run config (its ``task`` group), the group itself,
    or ``None`` (all defaults). Same checks and errors as ``config_of``."""
    task = group_of(cfg, "task")
    return config_of(config_cls, cfg if task is None else task, "task")
