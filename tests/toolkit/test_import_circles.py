"""No import circles between jt's modules (issue 27): toolkit and every built-in plugin package.

Every import counts, at module level or inside a function (a lazy import is still an arrow of the
house's drawing), except those under ``if TYPE_CHECKING:`` (annotations only, never executed) and
a module's import of its own parent package (Python imports the parent first anyway).
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def modules() -> dict[str, Path]:
    """``{dotted name: file}`` of toolkit and the plugin packages."""
    roots = [ROOT / "toolkit"] + [p for p in sorted((ROOT / "plugins").iterdir()) if (p / "__init__.py").exists()]
    out = {}
    for root in roots:
        for f in root.rglob("*.py"):
            parts = f.relative_to(root.parent).with_suffix("").parts
            out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = f
    return out


def _imports(tree: ast.AST):
    """Import nodes of ``tree``, skipping ``if TYPE_CHECKING:`` bodies."""
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            yield from (n for child in node.orelse for n in _imports_of(child))
            continue
        yield from _imports_of(node)


def _imports_of(node: ast.AST):
    if isinstance(node, (ast.Import, ast.ImportFrom)):
        yield node
    yield from _imports(node)


def arrows(mods: dict[str, Path]) -> dict[str, set[str]]:
    """``{module: modules it imports}`` among ``mods``."""
    out: dict[str, set[str]] = {m: set() for m in mods}
    for m, f in mods.items():
        package = m if f.name == "__init__.py" else m.rpartition(".")[0]
        for n in _imports(ast.parse(f.read_text())):
            if isinstance(n, ast.Import):
                names = [a.name for a in n.names]
            else:
                base = n.module or ""
                if n.level:
                    up = package.split(".")[: len(package.split(".")) - (n.level - 1)]
                    base = ".".join(up + ([n.module] if n.module else []))
                names = [base] + [f"{base}.{a.name}" for a in n.names]
            out[m].update(c for c in names if c in mods and c != m and not m.startswith(c + "."))
    return out


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected groups of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                found.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_no_module_imports_one_that_imports_it_back():
    mods = modules()
    assert len(mods) > 100 and "toolkit.policy.task" in mods and "jt_bullet.simulator" in mods
    assert circles(arrows(mods)) == []


def test_the_check_finds_a_circle():
    assert circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    tree = ast.parse("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import x\n"
                     "def f():\n    import y\n")
    assert [a.name for n in _imports(tree) if isinstance(n, ast.Import) for a in n.names] == ["y"]
