"""YAML names choices and the values a preset or paper changes: nothing that merely restates a default.

Every default lives in a plugin's ``Config`` dataclass (``toolkit.schema``). This walks every
config group file in ``conf/`` and every preset, and fails on a value equal to what it overrides —
the dataclass default for a group file, the group file's value (or the default) and the presets it
composes for a preset —
unless its line carries a citation comment (a paper code ``000``…``004``, "authors' code",
"paper", DeepMimic or SB3): a deliberate restatement that says where the value comes from.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import Any, Optional

import pytest

ROOT = Path(__file__).resolve().parents[2]
CONF = ROOT / "conf"
CITATION = re.compile(r"#.*(\b00[0-4]\b|authors'|paper|DeepMimic|SB3|Stable-Baselines)", re.IGNORECASE)


def _schema(group: str, name: Optional[str]) -> Optional[type]:
    from toolkit import plugins
    from toolkit.config import compose
    from toolkit.schema import CORE_GROUPS, _load_class

    if group in CORE_GROUPS:
        return _load_class(CORE_GROUPS[group])
    if group in plugins.KINDS and name:
        return getattr(plugins.load(group, str(name)), "Config", None)
    sim = plugins.load("sim", str(compose([]).sim.name))  # groups a simulator types (character)
    return (getattr(sim, "group_schemas", {}) or {}).get(group)


def _defaults(cls: type) -> dict[str, Any]:
    out = {}
    for f in dataclasses.fields(cls):
        if f.default is not dataclasses.MISSING:
            out[f.name] = f.default
        elif f.default_factory is not dataclasses.MISSING:  # type: ignore[misc]
            out[f.name] = f.default_factory()  # type: ignore[misc]
    return out


def _same(a: Any, b: Any) -> bool:
    b = list(b) if isinstance(b, tuple) else b
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool) and not isinstance(b, bool):
        return float(a) == float(b)
    return a == b


def _cited(text: str, key: str) -> bool:
    return any(re.match(rf"^\s*{re.escape(key)}\s*:", line) and CITATION.search(line) for line in text.splitlines())


def restatements(where: str, text: str, node: dict, schema: type, base: Optional[dict] = None) -> list[str]:
    """The keys of ``node`` (a group's values, raw YAML ``text``) equal to what they override:
    ``schema``'s defaults updated by ``base`` (the group file under a preset), uncited."""
    over = {**_defaults(schema), **(base or {})}
    return [f"{where}.{k} = {v!r}" for k, v in node.items()
            if k not in ("name", "defaults") and k in over and _same(v, over[k]) and not _cited(text, k)]


def _raw(path: Path) -> dict:
    from omegaconf import OmegaConf

    node = OmegaConf.to_container(OmegaConf.load(path))
    return node if isinstance(node, dict) else {}


def _inherited(preset: Path, group: str) -> dict:
    """The values of ``group`` that the presets in ``preset``'s defaults list give it (in order)."""
    out: dict = {}
    for entry in _raw(preset).get("defaults", []) or []:
        if isinstance(entry, str) and not entry.startswith(("override", "_self_")):
            parent = CONF / "preset" / f"{entry.split('/')[-1]}.yaml"
            if parent.exists():
                out.update(_inherited(parent, group))
                node = _raw(parent).get(group)
                out.update(node if isinstance(node, dict) else {})
    return out


def _all_restatements() -> list[str]:
    from toolkit.config import compose

    found = []
    for group_dir in sorted(p for p in CONF.iterdir() if p.is_dir() and p.name not in ("preset", "experiment", "reward")):
        for f in sorted(group_dir.glob("*.yaml")):
            node = {k: v for k, v in _raw(f).items() if k != "defaults"}
            schema = _schema(group_dir.name, node.get("name", f.stem))
            if schema is not None:
                found += restatements(f"{f.relative_to(ROOT)}: {group_dir.name}", f.read_text(), node, schema)
    for f in sorted((CONF / "preset").glob("*.yaml")):
        task = "spacetime" if f.stem.startswith("style_") else f.stem.split("_", 1)[1]
        cfg = compose([f"task={task}", f"preset={f.stem}"])
        for group, node in _raw(f).items():
            chosen = cfg.get(group)
            if not isinstance(node, dict) or chosen is None or not hasattr(chosen, "keys"):
                continue
            name = chosen.get("name") if "name" in chosen else None
            schema = _schema(group, name)
            if schema is None:
                continue
            own = CONF / group / f"{name}.yaml"
            base = {k: v for k, v in _raw(own).items() if k != "defaults"} if name and own.exists() else {}
            base.update(_inherited(f, group))  # a preset composing another overrides that one
            found += restatements(f"{f.relative_to(ROOT)}: {group}", f.read_text(), node, schema, base)
    return found


def test_no_yaml_value_restates_what_it_overrides():
    found = _all_restatements()
    assert not found, "values equal to what they override (drop them, or cite their source):\n" + "\n".join(found)


@dataclasses.dataclass
class _Example:
    rate: float = 30.0
    size: int = 4
    names: tuple = ("a", "b")


@pytest.mark.parametrize("text, node, base, flagged", [
    ("rate: 30\n", {"rate": 30}, None, ["x.rate = 30"]),                       # an int restating a float default
    ("rate: 30  # 002 §5\n", {"rate": 30}, None, []),                          # cited: deliberate
    ("size: 8\n", {"size": 8}, None, []),                                      # a change
    ("names: [a, b]\n", {"names": ["a", "b"]}, None, ["x.names = ['a', 'b']"]),
    ("size: 4\n", {"size": 4}, {"size": 16}, []),                              # a preset undoing its group file
    ("size: 16\n", {"size": 16}, {"size": 16}, ["x.size = 16"]),               # a preset restating its group file
])
def test_the_check_flags_restatements_and_spares_changes_and_citations(text, node, base, flagged):
    assert restatements("x", text, node, _Example, base) == flagged
