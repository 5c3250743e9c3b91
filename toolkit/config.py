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


@dataclasses.dataclass
class RunConfig:
    """Top-level keys of ``conf/config.yaml`` (the groups are checked by their plugins)."""

    seed: int = 0
    """Seed of the run; evaluation seeds derive from it."""
    store: str = "artifacts"
    """Store root: ``mlflow.db`` and artifact folders (``store=PATH`` or ``JT_STORE``)."""
    resume: Optional[str] = None
    """Run id of an interrupted run to continue instead of starting a new one."""
    profile: str = "default"
    """Name of the experiment preset applied (set by ``experiment=...``)."""
    run_name: Optional[str] = None
    """Optional MLflow run name."""


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
        try:
            parsed.extend(parser.parse_overrides([o]))
        except Exception as e:  # noqa: BLE001 - Hydra raises several types here
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


def compose(overrides: Sequence[str] = ()) -> Any:
    """Compose ``conf/config.yaml`` with ``overrides`` (Hydra syntax), checked and typed.

    Returns:
        An OmegaConf ``DictConfig``; plugin groups are typed by their plugins' ``Config``.

    Raises:
        JtError: one line naming what is wrong and, for choices, the valid ones.
    """
    from hydra import compose as hydra_compose
    from hydra import initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra

    overrides = list(overrides)
    parsed = _parse(overrides)
    _check_choices(parsed)
    extra = _search_path()
    if extra:
        overrides = overrides + ["hydra.searchpath=[" + ",".join(extra) + "]"]
    GlobalHydra.instance().clear()
    try:
        with initialize_config_dir(config_dir=str(conf_dir()), version_base=None):
            cfg = hydra_compose("config", overrides=overrides)
    except JtError:
        raise
    except Exception as e:  # noqa: BLE001 - Hydra/OmegaConf raise many types; one line each
        raise JtError(f"config: {_one_line(e)}") from e
    finally:
        GlobalHydra.instance().clear()
    return validate(cfg)


def validate(cfg: Any) -> Any:
    """Type-check the top level and each plugin group against its plugin's ``Config``."""
    from omegaconf import OmegaConf

    OmegaConf.set_struct(cfg, False)
    top = {k: cfg[k] for k in (f.name for f in dataclasses.fields(RunConfig)) if k in cfg}
    try:
        OmegaConf.merge(OmegaConf.structured(RunConfig), top)
    except Exception as e:  # noqa: BLE001
        raise JtError(f"config: {_one_line(e)}") from e
    for group in plugins.KINDS:
        node = cfg.get(group)
        if node is None or not OmegaConf.is_dict(node) or "name" not in node:
            continue
        cls = plugins.load(group, str(node.name))
        cfg[group] = typed_group(group, cls, node)
    OmegaConf.set_struct(cfg, True)
    return cfg


def typed_group(group: str, cls: Any, node: Any) -> Any:
    """Merge a group node into the plugin's ``Config`` schema (unknown key / wrong type → JtError)."""
    from omegaconf import OmegaConf

    schema_cls = getattr(cls, "Config", None)
    if schema_cls is None or not dataclasses.is_dataclass(schema_cls):
        return node
    schema = OmegaConf.structured(schema_cls)
    if "name" not in schema:
        OmegaConf.set_struct(schema, False)
        schema.name = str(node.name)
        OmegaConf.set_struct(schema, True)
    try:
        return OmegaConf.merge(schema, node)
    except Exception as e:  # noqa: BLE001
        msg = str(e).strip().splitlines()[0]
        if "not in" in msg or "Key '" in msg:
            valid = ", ".join(f.name for f in dataclasses.fields(schema_cls) if f.name != "name")
            raise JtError(f"{group}={node.name}: {msg} (valid keys: {valid})") from e
        key = getattr(e, "full_key", None)
        where = f"{group}.{key}" if key else f"{group}={node.name}"
        raise JtError(f"{where}: {msg}") from e


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


def config_of(config_cls: type, cfg: Any, what: str = "config") -> Any:
    """A typed ``Config`` dataclass instance from ``None``, an instance, a dataclass, a dict or a
    group node — the one way every plugin parses its parameters.

    Values are type-checked and converted through OmegaConf's structured configs (``"0.7"`` is
    rejected for a float, ``1`` becomes ``1.0``). A ``name`` key is dropped unless ``config_cls``
    declares it.

    Args:
        config_cls: the plugin's ``Config`` dataclass.
        cfg: its parameters.
        what: how to name the plugin in an error (``reward term safety``).

    Raises:
        JtError: an unknown key (the message lists the valid ones) or a value of the wrong type.
    """
    if cfg is None:
        return config_cls()
    if isinstance(cfg, config_cls):
        return cfg
    from omegaconf import OmegaConf

    if dataclasses.is_dataclass(cfg):
        params = dataclasses.asdict(cfg)
    elif isinstance(cfg, dict):
        params = dict(cfg)
    else:
        params = OmegaConf.to_container(cfg, resolve=True)
    known = {f.name for f in dataclasses.fields(config_cls)}
    if "name" not in known:
        params.pop("name", None)
    unknown = sorted(set(params) - known)
    if unknown:
        valid = ", ".join(sorted(known - {"name"}))
        raise JtError(f"{what}: unknown key(s) {', '.join(unknown)} (valid keys: {valid})")
    try:
        return OmegaConf.to_object(OmegaConf.merge(OmegaConf.structured(config_cls), params))
    except Exception as e:  # noqa: BLE001 - OmegaConf raises several validation types
        msg = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        key = getattr(e, "full_key", None)
        raise JtError(f"{what}: {key + ': ' if key else ''}{msg}") from e


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
