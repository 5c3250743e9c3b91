"""Entry-point plugin registry: every plugin, built-in or third-party, is found the same way.

Each kind of plugin is an entry-point group (``jt.spd``, ``jt.tasks``, ...). Listing reads only
package metadata; a plugin's module is imported when the plugin is loaded (``load``) or described
(``describe``). Plugin modules import heavy packages (torch, pybullet) inside functions, so
describing all of them stays fast.
"""

from __future__ import annotations

import dataclasses
import functools
from importlib import metadata
from typing import Any, Optional

from toolkit.errors import BrokenPlugin, JtError, UnknownPlugin

#: config group name → entry-point group. The config group of a kind has the kind's name.
KINDS: dict[str, str] = {
    "task": "jt.tasks",
    "sim": "jt.simulators",
    "spd": "jt.spd",
    "action": "jt.actions",
    "reward": "jt.rewards",
    "curriculum": "jt.curricula",
    "search": "jt.searchers",
    "executor": "jt.executors",
}

#: entry-point group whose values name packages holding config groups (``<group>/<name>.yaml``).
CONFIG_GROUP = "jt.config"

_ALIASES = {
    "tasks": "task", "simulator": "sim", "simulators": "sim", "actions": "action",
    "rewards": "reward", "curricula": "curriculum", "searcher": "search", "searchers": "search",
    "executors": "executor",
}


def kind_of(word: str) -> Optional[str]:
    """Canonical kind for ``word`` (``searchers`` → ``search``), or None."""
    word = word.strip().lower()
    if word in KINDS:
        return word
    return _ALIASES.get(word)


@dataclasses.dataclass(frozen=True)
class PluginInfo:
    """One registered plugin, from package metadata alone.

    Attributes:
        kind: config group / kind name (``spd``).
        name: plugin name (``maba``).
        value: entry-point value, ``module:attr``.
        dist: the distribution that registered it (``jt`` for built-ins).
    """

    kind: str
    name: str
    value: str
    dist: str


@functools.lru_cache(maxsize=None)
def _entry_points(group: str) -> tuple[metadata.EntryPoint, ...]:
    eps = metadata.entry_points(group=group)
    seen: dict[str, metadata.EntryPoint] = {}
    for ep in eps:
        seen.setdefault(ep.name, ep)  # first wins if a name is registered twice
    return tuple(sorted(seen.values(), key=lambda e: e.name))


def refresh() -> None:
    """Forget cached metadata (after installing a package in-process, e.g. in tests)."""
    _entry_points.cache_clear()
    load.cache_clear()


def available(kind: str) -> list[PluginInfo]:
    """Every plugin of ``kind`` (no imports)."""
    out = []
    for ep in _entry_points(KINDS[kind]):
        dist = ep.dist.name if getattr(ep, "dist", None) is not None else "?"
        out.append(PluginInfo(kind=kind, name=ep.name, value=ep.value, dist=dist))
    return out


def names(kind: str) -> list[str]:
    """Names of the plugins of ``kind``, sorted."""
    return [p.name for p in available(kind)]


def sole(kind: str, what: str) -> str:
    """The name of the one installed plugin of ``kind`` (e.g. the simulator when a hand-written
    config names none); one ``JtError`` line naming the choices when there is not exactly one.

    Args:
        kind: a plugin kind (``sim``, ``spd`` ...).
        what: the setting that picks one, for the message (e.g. ``sim.name``, ``--sim``).
    """
    found = names(kind)
    if len(found) != 1:
        raise JtError(f"{what} is not set; choose one of: {', '.join(found) or '(none installed)'}")
    return found[0]


@functools.lru_cache(maxsize=None)
def load(kind: str, name: str) -> Any:
    """Import and return the plugin class ``name`` of ``kind``.

    Raises:
        UnknownPlugin: no such plugin (the message lists the choices).
        BrokenPlugin: the plugin's module fails to import.
    """
    if kind not in KINDS:
        raise UnknownPlugin("plugin kind", kind, sorted(KINDS))
    for ep in _entry_points(KINDS[kind]):
        if ep.name == name:
            try:
                cls = ep.load()
            except Exception as e:  # noqa: BLE001 - any import failure makes the plugin broken
                raise BrokenPlugin(kind, name, f"{type(e).__name__}: {e}") from e
            try:
                cls.name = name
            except (AttributeError, TypeError):
                pass
            return cls
    raise UnknownPlugin(kind, name, names(kind))


def describe(info: PluginInfo) -> tuple[str, str]:
    """``(status, summary)`` of a plugin: ``ok`` and its docstring line, or ``broken`` and why."""
    try:
        cls = load(info.kind, info.name)
    except BrokenPlugin as e:
        return "broken", e.reason
    doc = (getattr(cls, "__doc__", None) or "").strip()
    return "ok", doc.splitlines()[0].strip() if doc else ""


def config_packages() -> list[tuple[str, str]]:
    """``(distribution, package)`` of every installed package that ships config groups."""
    out = []
    for ep in _entry_points(CONFIG_GROUP):
        dist = ep.dist.name if getattr(ep, "dist", None) is not None else "?"
        out.append((dist, ep.value.split(":")[0]))
    return out
