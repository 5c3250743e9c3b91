"""Config schemas: every group typed by its ``Config`` dataclass, the one source of defaults.

A default lives once, in a plugin's ``Config`` dataclass (each field with a docstring citing its
source); YAML only selects and overrides. ``toolkit.config.compose`` lets Hydra compose the
defaults lists (groups, presets, packages), then ``validate`` merges each group node into its
schema and applies the command line's ``group.key=value`` overrides on the typed node, so that

* an unknown key or a wrong type is one ``JtError`` line before anything runs,
* a ``Config`` with a ``check()`` method range-checks its values there too,
* ``jt run ... --cfg`` prints every value that will run, defaults included.

Which schema types a group:

* a plugin kind's group (``task``, ``spd``, ``search``, ...): the chosen plugin's ``Config``,
  and the keys its interface declares for every plugin of the kind (``common_keys``: the
  ``executor`` group's ``workers``) that ``Config`` does not (``_common_keys``);
* ``reward`` (a *set* of terms, no ``name``): each ``terms.<term>`` by that term's ``Config``;
* groups a plugin declares in ``group_schemas`` (the ``bullet`` simulator types ``character``);
* the core's own groups in ``CORE_GROUPS`` (``agent``: PPO's hyper-parameters).
"""

from __future__ import annotations

import dataclasses
import importlib
import math
from typing import Any, Optional, Sequence

from toolkit import plugins
from toolkit.errors import JtError

#: groups typed by the core (not plugin kinds): group → ``module:Class``
CORE_GROUPS: dict[str, str] = {"agent": "toolkit.rl.config:PPOConfig"}


@dataclasses.dataclass
class RunConfig:
    """Top-level keys of ``conf/config.yaml`` (the groups are checked by their schemas)."""

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
    cost: Optional[str] = None
    """What the run costs, in one line ``jt run`` prints before it starts (a preset says it, e.g.
    the paper's budget and the cheaper experiment to try on a laptop)."""


def _load_class(ref: str) -> type:
    module, _, attr = ref.partition(":")
    return getattr(importlib.import_module(module), attr)


def _first_line(e: BaseException) -> str:
    text = str(e).strip()
    return text.splitlines()[0].strip() if text else type(e).__name__


def _valid_keys(cls: type) -> str:
    return ", ".join(f.name for f in dataclasses.fields(cls) if f.name != "name")


def structured(cls: type, name: Optional[str] = None) -> Any:
    """The OmegaConf structured node of dataclass ``cls`` (struct: unknown keys are refused);
    a ``name`` key is added when ``cls`` has none and ``name`` is given."""
    from omegaconf import OmegaConf

    node = OmegaConf.structured(cls)
    if name is not None and "name" not in node:
        OmegaConf.set_struct(node, False)
        node.name = str(name)
        OmegaConf.set_struct(node, True)
    return node


def typed_node(where: str, cls: type, node: Any, overrides: Sequence[tuple[str, Any]] = ()) -> Any:
    """``node`` merged into ``cls``'s schema, then ``overrides`` ``[(dotted key, value)]`` applied.

    Args:
        where: how to name the group in an error (``task=highjump``, ``agent``).
        cls: the schema dataclass.
        node: the composed group node (DictConfig / dict / None).
        overrides: command-line assignments inside this group, keys relative to it.

    Returns:
        The typed DictConfig.

    Raises:
        JtError: one line: an unknown key (with the valid ones), a wrong type, a value out of range.
    """
    from omegaconf import OmegaConf

    name = None if node is None or "name" not in node else str(node["name"])
    schema = structured(cls, name)
    group = where.split("=")[0]
    try:
        merged = OmegaConf.merge(schema, node if node is not None else {})
    except Exception as e:  # noqa: BLE001 - OmegaConf raises several validation types
        raise _schema_error(where, cls, e) from e
    for key, value in overrides:
        try:
            try:
                OmegaConf.update(merged, key, value, merge=True, force_add=False)
            except Exception as e:  # noqa: BLE001 - [[0, 0.5]] for a list of float lists: say 0.0
                if "(int) is incompatible with type hint 'float'" not in str(e):
                    raise
                OmegaConf.update(merged, key, _floats(value), merge=True, force_add=False)
        except Exception as e:  # noqa: BLE001
            msg = _first_line(e)
            if "not in" in msg or "Key '" in msg or "Could not" in msg:
                raise JtError(f"unknown key '{group}.{key}' ({where}; valid keys: {_valid_keys(cls)})") from e
            raise JtError(f"{group}.{key}={value}: {msg}") from e
    return merged


def _floats(value: Any) -> Any:
    """``value`` with every int inside lists turned into a float (OmegaConf does not widen them)."""
    if isinstance(value, (list, tuple)):
        return [_floats(v) for v in value]
    return float(value) if isinstance(value, int) and not isinstance(value, bool) else value


def check_node(where: str, cls: type, node: Any) -> None:
    """Build the dataclass of a typed node in place (interpolations resolve against its root) and
    run its ``check()``: a missing value or a bad range is one ``JtError`` line."""
    from omegaconf import OmegaConf

    try:
        obj = OmegaConf.to_object(node)
    except Exception as e:  # noqa: BLE001 - e.g. a missing mandatory value
        raise _schema_error(where, cls, e) from e
    require_finite(where.split("=")[0], obj)
    check = getattr(obj, "check", None)
    if callable(check):
        check()


def require_finite(where: str, obj: Any) -> None:
    """Every number in a config object (its fields, lists and mappings, nested) is finite: NaN
    never is, ±inf only in the fields its class names in ``NONFINITE_OK`` (e.g. a bound width
    that ``.inf`` switches off).

    Raises:
        JtError: ``<group>.<key>=nan: must be a finite number`` (one line).
    """
    def walk(path: str, value: Any, inf_ok: bool) -> None:
        if isinstance(value, bool) or value is None:
            return
        if isinstance(value, float):
            if math.isnan(value) or (math.isinf(value) and not inf_ok):
                what = "a number (not NaN)" if inf_ok else "a finite number"
                raise JtError(f"{path}={value}: must be {what}")
        elif dataclasses.is_dataclass(value) and not isinstance(value, type):
            allowed = set(getattr(type(value), "NONFINITE_OK", ()))
            for f in dataclasses.fields(value):
                walk(f"{path}.{f.name}", getattr(value, f.name), inf_ok or f.name in allowed)
        elif isinstance(value, dict):
            for k, v in value.items():
                walk(f"{path}.{k}", v, inf_ok)
        elif isinstance(value, (list, tuple)):
            for v in value:
                walk(path, v, inf_ok)

    walk(where, obj, False)


def _schema_error(where: str, cls: type, e: BaseException) -> JtError:
    msg = _first_line(e)
    group = where.split("=")[0]
    if "not in" in msg or "Key '" in msg:
        return JtError(f"{where}: {msg} (valid keys: {_valid_keys(cls)})")
    key = getattr(e, "full_key", None)
    return JtError(f"{group + '.' + key if key else where}: {msg}")


def _typed_reward(node: Any, overrides: Sequence[tuple[str, Any]]) -> Any:
    """The reward group: ``terms.<term>`` each typed by the term plugin's ``Config``."""
    from omegaconf import OmegaConf

    terms = OmegaConf.to_container(node, resolve=False).get("terms") or {}
    by_term: dict[str, list] = {}
    for key, value in overrides:
        parts = key.split(".")
        if parts[0] != "terms" or len(parts) < 2:
            raise JtError(f"unknown key 'reward.{key}' (the reward group holds terms.<term>.<key>)")
        if parts[1] not in terms:
            raise JtError(f"reward.{key}: the reward has no term '{parts[1]}'; its terms: {', '.join(terms)}")
        if len(parts) == 2:
            by_term.setdefault(parts[1], []).extend((k, v) for k, v in dict(value).items())
        else:
            by_term.setdefault(parts[1], []).append((".".join(parts[2:]), value))
    typed = {}
    for term, params in terms.items():
        cls = getattr(plugins.load("reward", term), "Config", None)
        if cls is None or not dataclasses.is_dataclass(cls):
            typed[term] = params
            continue
        typed[term] = typed_node(f"reward.terms.{term}", cls, params or {}, by_term.get(term, ()))
        check_node(f"reward.terms.{term}", cls, typed[term])
    out = OmegaConf.create({"terms": typed})
    OmegaConf.set_struct(out, True)
    return out


def _plugin_schema(group: str, node: Any) -> tuple[Optional[type], Optional[type]]:
    """``(plugin class, schema)`` of a plugin-kind group node (``(None, None)`` if untyped)."""
    if node is None or "name" not in node:
        return None, None
    cls = plugins.load(group, str(node["name"]))
    schema = getattr(cls, "Config", None)
    return cls, schema if schema is not None and dataclasses.is_dataclass(schema) else None


def _common_keys(where: str, cls: type, schema: type, node: Any,
                 overrides: Sequence[tuple[str, Any]]) -> tuple[Any, list[tuple[str, Any]]]:
    """Split the keys an interface declares for every plugin of its kind (the plugin class's
    ``common_keys`` dataclass, e.g. ``ExecutorKeys``) but the plugin's ``Config`` does not off a
    group node and its overrides: they are typed and checked against ``common_keys``, then left
    out, so the plugin is built from exactly the keys it declares.

    Args:
        where: how to name the group in an error (``executor=tp_serial``).
        cls: the chosen plugin class.
        schema: its ``Config``.
        node: the composed group node.
        overrides: command-line assignments inside the group.

    Returns:
        ``(node, overrides)`` without those keys (unchanged when there are none).

    Raises:
        JtError: one line: a wrong type or a value out of range.
    """
    from omegaconf import OmegaConf

    common = getattr(cls, "common_keys", None)
    if common is None or not dataclasses.is_dataclass(common):
        return node, list(overrides)
    keys = {f.name for f in dataclasses.fields(common)} - {f.name for f in dataclasses.fields(schema)}
    if not keys:
        return node, list(overrides)
    plain = OmegaConf.to_container(node, resolve=False) if OmegaConf.is_config(node) else dict(node or {})
    given = {k: plain.pop(k) for k in list(plain) if k in keys}
    mine = [(k, v) for k, v in overrides if k.split(".")[0] in keys]
    if given or mine:
        check_node(where, common, typed_node(where, common, given, mine))
    return plain, [(k, v) for k, v in overrides if k.split(".")[0] not in keys]


#: the groups a config may lack (no default): present means chosen, by a preset or the command line
OPTIONAL_GROUPS = ("action", "reward", "curriculum")


def _never_read(task: str, group: str, drop: str) -> JtError:
    article = "an" if group[0] in "aeiou" else "a"
    return JtError(f"task={task} does not read {article} {group} group; drop {drop} (it would be ignored)")


def ignored_choice(task: str, key: str, value: Any) -> None:
    """A command-line ``key=value`` (a group choice or ``group.field=...``) for a group with a
    default that ``task`` never reads (``Task.ignores_groups``): one ``JtError`` line."""
    group = key.split(".")[0]
    if group in OPTIONAL_GROUPS or task not in plugins.names("task"):
        return
    if group in getattr(plugins.load("task", task), "ignores_groups", ()):
        raise _never_read(task, group, f"{key}={value}")


def run_checks(cfg: Any) -> None:
    """The chosen plugins' cross-group checks (``Plugin.check_run``) of a validated config, and
    no optional group chosen that the task never reads (``Task.ignores_groups``)."""
    task = cfg.get("task")
    if task is not None and "name" in task:
        ignored = getattr(plugins.load("task", str(task["name"])), "ignores_groups", ())
        chosen = [g for g in ignored if g in OPTIONAL_GROUPS and cfg.get(g) is not None]
        if chosen:
            g = chosen[0]
            what = cfg[g].get("name", "") if hasattr(cfg[g], "get") else ""
            raise _never_read(str(task["name"]), g, f"{g}={what}" if what else f"the {g}= choice")
    if task is not None and "name" in task:
        check_declared_needs(cfg, plugins.load("task", str(task["name"])))
    for group in plugins.KINDS:
        node = cfg.get(group)
        if node is not None and "name" in node and group != "reward":
            plugins.load(group, str(node["name"])).check_run(cfg)


def check_declared_needs(cfg: Any, task_cls: type) -> None:
    """What the chosen reward terms, action space, SPD backend and curriculum need against what the
    task says it provides or needs (``Task.record_keys``, ``action_inputs``, ``needs_spd_torques``,
    ``curriculum_attrs``; an undeclared side is not checked): one ``JtError`` line naming both
    sides, before a run opens."""
    name = str(cfg.task["name"])
    provided = getattr(task_cls, "record_keys", None)
    reward = cfg.get("reward")
    if provided is not None and reward is not None and reward.get("terms"):
        for term, params in dict(reward["terms"]).items():
            missing = sorted(plugins.load("reward", str(term)).needs(params or {}) - set(provided))
            if missing:
                raise JtError(f"reward term {term} reads record key(s) {', '.join(missing)}, which task={name}'s "
                              f"records do not have (they have: {', '.join(sorted(provided))})")
    inputs = getattr(task_cls, "action_inputs", None)
    action = cfg.get("action")
    if inputs is not None and action is not None and "name" in action:
        needs = set(getattr(plugins.load("action", str(action["name"])), "needs", frozenset()))
        if needs - set(inputs):
            raise JtError(f"action={action['name']} needs {', '.join(sorted(needs - set(inputs)))} from the task, which "
                          f"task={name} does not give (it gives: {', '.join(sorted(inputs)) or 'nothing'})")
    spd = cfg.get("spd")
    if getattr(task_cls, "needs_spd_torques", False) and spd is not None and "name" in spd \
            and getattr(plugins.load("spd", str(spd["name"])), "steps_itself", False):
        able = [n for n in plugins.names("spd") if not getattr(plugins.load("spd", n), "steps_itself", False)]
        raise JtError(f"spd={spd['name']} computes its torques inside the simulator's step, and task={name} needs "
                      f"the torques; use one of: {', '.join(able)}")
    attrs = getattr(task_cls, "curriculum_attrs", None)
    cur = cfg.get("curriculum")
    if attrs is not None and cur is not None and "name" in cur:
        driven = plugins.load("curriculum", str(cur["name"])).drives(cur) - set(attrs)
        if driven:
            raise JtError(f"curriculum={cur['name']} drives {', '.join(sorted(driven))}, which task={name}'s env does "
                          f"not have (a curriculum for it drives: {', '.join(sorted(attrs)) or 'nothing'})")


def validate(cfg: Any, overrides: Sequence[tuple[str, Any]] = (), run_checks_too: bool = True) -> Any:
    """Type every group of a composed config and apply the deferred group overrides.

    Args:
        cfg: Hydra's composed DictConfig.
        overrides: ``[(dotted key, value)]`` assignments inside groups (``task.clip``), applied on
            the typed nodes so that an unknown key names the group's valid keys.
        run_checks_too: also run the chosen plugins' cross-group checks (``run_checks``).

    Returns:
        The validated config, struct (reading or setting an unknown key raises).
    """
    from omegaconf import OmegaConf

    OmegaConf.set_struct(cfg, False)
    if cfg.get("task") is None or "name" not in cfg.task:  # e.g. ~task: every run is a task's
        raise JtError(f"a run needs a task: task=<name>; choose one of: {', '.join(plugins.names('task'))}")
    by_group: dict[str, list[tuple[str, Any]]] = {}
    for key, value in overrides:
        group, _, rest = key.partition(".")
        by_group.setdefault(group, []).append((rest, value))
    allowed = {f.name for f in dataclasses.fields(RunConfig)} | set(plugins.KINDS) | set(CORE_GROUPS)
    schemas: dict[str, type] = {}
    checks: list[tuple[str, type, str]] = []
    for group in plugins.KINDS:
        node = cfg.get(group)
        if group == "reward":
            if node is not None:
                cfg[group] = _typed_reward(node, by_group.pop(group, ()))
            continue
        cls, schema = _plugin_schema(group, node)
        if cls is not None:
            schemas.update(getattr(cls, "group_schemas", {}) or {})
        if schema is not None:
            where = f"{group}={node['name']}"
            node, own = _common_keys(where, cls, schema, node, by_group.pop(group, ()))
            cfg[group] = typed_node(where, schema, node, own)
            checks.append((where, schema, group))
    schemas.update({g: _load_class(ref) for g, ref in CORE_GROUPS.items()})
    for group, schema in schemas.items():
        allowed.add(group)
        if group in cfg:
            cfg[group] = typed_node(group, schema, cfg.get(group), by_group.pop(group, ()))
            checks.append((group, schema, group))
    for where, schema, group in checks:  # attached to the root now: ${store} etc. resolve
        check_node(where, schema, cfg[group])
    if run_checks_too:  # cross-group checks of the chosen plugins (Plugin.check_run)
        run_checks(cfg)
    for group, items in by_group.items():  # groups without a schema: plain struct updates
        node = cfg.get(group)
        if node is None or not OmegaConf.is_dict(node):
            hint = f"choose one first: {group}=<{', '.join(plugins.names(group))}>" if group in plugins.KINDS \
                else "no such group"
            raise JtError(f"{group}.{items[0][0]}: no {group} is selected ({hint})")
        OmegaConf.set_struct(node, True)
        for key, value in items:
            try:
                OmegaConf.update(node, key, value, merge=True)
            except Exception as e:  # noqa: BLE001
                raise JtError(f"unknown key '{group}.{key}'") from e
    allowed |= {k for k in cfg if OmegaConf.is_dict(cfg.get(k))}
    unknown = sorted(k for k in cfg if k not in allowed)
    if unknown:
        raise JtError(f"unknown top-level key(s) {', '.join(unknown)}; top-level keys: "
                      f"{', '.join(f.name for f in dataclasses.fields(RunConfig))} and the groups")
    top = {k: cfg[k] for k in (f.name for f in dataclasses.fields(RunConfig)) if k in cfg}
    try:
        OmegaConf.merge(OmegaConf.structured(RunConfig), top)
    except Exception as e:  # noqa: BLE001
        raise _schema_error("config", RunConfig, e) from e
    if "seed" in cfg and int(cfg.seed) < 0:
        raise JtError(f"seed={cfg.seed}: must be an integer >= 0")
    if "store" in cfg and not str(cfg.store).strip():
        raise JtError("store= is empty: give a folder (store=PATH) or leave it out (./artifacts, or $JT_STORE)")
    OmegaConf.set_struct(cfg, True)
    return cfg


def config_of(config_cls: type, cfg: Any, what: str = "config") -> Any:
    """A typed ``Config`` dataclass instance from ``None``, an instance, a dataclass, a dict or a
    group node — the one way every plugin parses its parameters.

    Values are type-checked and converted through OmegaConf's structured configs (``"0.7"`` is
    rejected for a float, ``1`` becomes ``1.0``); a ``check()`` method of ``config_cls`` runs on
    the result. A ``name`` key is dropped unless ``config_cls`` declares it.

    Args:
        config_cls: the plugin's ``Config`` dataclass.
        cfg: its parameters.
        what: how to name the plugin in an error (``reward term safety``).

    Raises:
        JtError: an unknown key (the message lists the valid ones), a wrong type, a bad value.
    """
    if cfg is None:
        obj = config_cls()
    elif isinstance(cfg, config_cls):
        obj = cfg
    else:
        obj = _to_object(config_cls, cfg, what)
    check = getattr(obj, "check", None)
    if callable(check):
        check()
    return obj


def _to_object(config_cls: type, cfg: Any, what: str) -> Any:
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
        key = getattr(e, "full_key", None)
        raise JtError(f"{what}: {key + ': ' if key else ''}{_first_line(e)}") from e


def require(ok: bool, where: str, value: Any, rule: str) -> None:
    """Raise ``JtError("{where}={value}: {rule}")`` unless ``ok`` — for ``Config.check()``."""
    if not ok:
        raise JtError(f"{where}={value}: {rule}")


def finite(x: Any) -> bool:
    """True for a finite number (``None`` and NaN/inf are not)."""
    try:
        return x is not None and math.isfinite(float(x))
    except (TypeError, ValueError):
        return False
