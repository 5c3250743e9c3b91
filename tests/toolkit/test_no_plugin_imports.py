"""``toolkit/`` imports no physics engine and no plugin (issue 27): what needs PyBullet lives in the
simulator plugin, and plugins are reached through the registry only.

Every module under ``toolkit/`` is imported in a fresh interpreter whose plugin registry is empty
(the registry is the one sanctioned way to a plugin: ``toolkit.gym_envs`` loads every task plugin
through it on import); afterwards neither ``pybullet`` nor any plugin package (the top-level
packages of ``pyproject.toml``'s entry points) may be in ``sys.modules``. And, since most imports
sit inside functions, no source line under ``toolkit/`` imports pybullet (or pybullet_data) or a
plugin package.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import toolkit

ROOT = Path(toolkit.__file__).resolve().parents[1]
TOOLKIT = ROOT / "toolkit"


def _imports_of(packages: set[str]) -> re.Pattern:
    """A source line importing one of ``packages`` (or a module of one)."""
    names = "|".join(sorted(map(re.escape, packages)))
    return re.compile(rf"^\s*(import|from)\s+({names})\b", re.M)


def plugin_packages() -> set[str]:
    """Top-level packages of every entry point jt registers (``jt_bullet``, ``jt_tasks`` ...)."""
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    groups = meta["project"].get("entry-points", {})
    return {value.split(":")[0].split(".")[0] for group, eps in groups.items() if group.startswith("jt.")
            for value in eps.values()}


def imported_after_every_toolkit_module() -> dict:
    """Import every toolkit module in a fresh interpreter with no plugin registered; what of
    ``sys.modules`` is then there."""
    code = """
import importlib, json, pkgutil, sys
import toolkit
import toolkit.plugins
toolkit.plugins._entry_points = lambda group: ()  # only a direct import can reach a plugin now
failed = {}
for m in pkgutil.walk_packages(toolkit.__path__, "toolkit."):
    try:
        importlib.import_module(m.name)
    except Exception as e:  # a module that needs an optional package: reported, not hidden
        failed[m.name] = f"{type(e).__name__}: {e}"
print(json.dumps({"modules": sorted(sys.modules), "failed": failed}))
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT,
                         timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_the_plugin_packages_are_known():
    assert {"jt_bullet", "jt_tasks", "jt_spd", "jt_actions", "jt_rewards", "jt_searchers",
            "jt_curricula", "jt_executors"} <= plugin_packages()


def test_importing_every_toolkit_module_loads_no_pybullet_and_no_plugin():
    got = imported_after_every_toolkit_module()
    assert not got["failed"], got["failed"]
    loaded = {m.split(".")[0] for m in got["modules"]}
    assert "pybullet" not in loaded
    assert not loaded & plugin_packages(), sorted(loaded & plugin_packages())


def test_no_toolkit_source_line_imports_pybullet_or_a_plugin():
    pattern = _imports_of({"pybullet", "pybullet_data"} | plugin_packages())
    hits = [f"{p.relative_to(ROOT)}:{text[:m.start()].count(chr(10)) + 1}: {m.group(0).strip()}"
            for p in sorted(TOOLKIT.rglob("*.py")) for text in [p.read_text()]
            for m in pattern.finditer(text)]
    assert not hits, "\n".join(hits)


def test_the_source_check_sees_an_import():
    """The pattern finds what it must (an import inside a function too) and nothing else."""
    pattern = _imports_of({"pybullet", "jt_bullet"})
    text = "def f():\n    import pybullet as pb\n    from jt_bullet.characters import load\n"
    assert len(pattern.findall(text)) == 2
    assert not pattern.search("x = 1  # from pybullet_data's clips\nimport pybullet_data\n")


# ---------------------------------------------------------------- names in code (issue 54)

#: Where ``toolkit/`` may still name a plugin in code, and why: the core's own algorithms and file
#: formats share a plugin's name, a benchmark's documented default, the shared suites' reference
#: task. Anything else is a plugin name the core should have asked the registry or the config for.
ALLOWED = {
    "toolkit/dynamics/spd.py": {"maba", "df", "sf", "pcg"},  # the core's SPD algorithms (jt_spd wraps them)
    "toolkit/priors/io.py": {"pvae", "pose_prior"},  # a prior file's kind (the P-VAE / C-VAE formats are
    # core), and the command that trains one in its messages
    "toolkit/priors/model.py": {"pvae", "cvae"},
    "toolkit/priors/train.py": {"cvae"},
    "toolkit/priors/vae.py": {"pvae", "cvae"},
    "toolkit/policy/task.py": {"raw"},  # "(or use action=raw)": the fix a missing prior's message offers
    "toolkit/bench_cli.py": {"highjump"},  # jt bench rollout's documented default task (--tasks)
    "toolkit/rl/rollout_bench.py": {"raw", "local"},  # the benchmark's fallback actions, its process pool
    "toolkit/rl/sanity.py": {"local"},  # jt bench ppo's process pool
    "toolkit/testing/curriculum.py": {"zdt1"},  # the shared suites' reference task
    "toolkit/testing/executor.py": {"zdt1"},
    "toolkit/testing/spd.py": {"df"},  # the shared SPD suite's reference backend
}


def plugin_names() -> set[str]:
    """Every plugin name jt registers (``bullet``, ``maba``, ``pvae``, ``highjump`` ...)."""
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    return {name for group, eps in meta["project"].get("entry-points", {}).items()
            if group.startswith("jt.") and group != "jt.config" for name in eps}


def named_plugins(text: str, names: set[str]) -> set[str]:
    """Plugin names in ``text``'s string literals (docstrings left out): a literal that is a name,
    or a short one with a name as a word (``"action=raw"``, ``"df,sf"``)."""
    import ast

    tree = ast.parse(text)
    docs = {id(n.body[0].value) for n in ast.walk(tree)
            if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and n.body
            and isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant)}
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs:
            words = set(re.split(r"[\s,=()\[\]:;]+", node.value))
            found |= {node.value} & names if len(node.value) >= 80 else words & names
    return found


def test_no_toolkit_code_names_a_plugin():
    """Lists of backends, the simulator, the character, the prior-needing action spaces and a
    task's cheap settings come from the registry, the config or the plugin itself (issue 54)."""
    names = plugin_names()
    hits = {}
    for p in sorted(TOOLKIT.rglob("*.py")):
        rel = str(p.relative_to(ROOT))
        extra = named_plugins(p.read_text(), names) - ALLOWED.get(rel, set())
        if extra:
            hits[rel] = sorted(extra)
    assert not hits, hits


def test_the_allowed_names_are_still_there():
    """An allowance the code no longer needs is removed (so the list stays the truth)."""
    names = plugin_names()
    stale = {rel: sorted(allowed - named_plugins((ROOT / rel).read_text(), names))
             for rel, allowed in ALLOWED.items()}
    assert not {k: v for k, v in stale.items() if v}, stale


def test_the_name_check_sees_a_name():
    text = 'def f():\n    """Uses bullet."""\n    return load("sim", "bullet"), "action=raw", "x = 1"\n'
    assert named_plugins(text, {"bullet", "raw", "maba"}) == {"bullet", "raw"}
