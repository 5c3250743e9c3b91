"""conf/search/*.yaml against the searchers' Config dataclasses; cheap module imports."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from pathlib import Path

import pytest
from omegaconf import OmegaConf

from toolkit.config import config_of as build_config
from toolkit.errors import JtError
from jt_searchers.bds import BDSSearcher
from jt_searchers.bsoo import BSOOSearcher
from jt_searchers.random_search import RandomSearcher
from jt_searchers.rmoo import RMOOSearcher

ROOT = Path(__file__).parents[3]
SEARCHERS = {"random": RandomSearcher, "bds": BDSSearcher, "rmoo": RMOOSearcher, "bsoo": BSOOSearcher}


@pytest.mark.parametrize("name", sorted(SEARCHERS))
def test_defaults_live_once_in_the_config_with_their_sources(name: str) -> None:
    """One source: the YAML only selects the searcher; every default is a Config field with a
    docstring (its source), and what composition gives the plugin is exactly Config()."""
    from toolkit.config import compose
    from toolkit.schema import _load_class  # noqa: F401 - the schema module types the group

    path = ROOT / "conf" / "search" / f"{name}.yaml"
    node = OmegaConf.load(path)
    cls = SEARCHERS[name]
    assert node.name == name and set(node) == {"name"}
    cfg = compose([f"search={name}", "task=zdt1"])
    assert build_config(cls.Config, cfg.search) == cls.Config()
    import ast
    import inspect
    import textwrap

    tree = ast.parse(textwrap.dedent(inspect.getsource(cls.Config)))
    body = tree.body[0].body
    documented = {a.target.id for a, b in zip(body, body[1:])
                  if isinstance(a, ast.AnnAssign) and isinstance(b, ast.Expr) and isinstance(b.value, ast.Constant)}
    assert {f.name for f in dataclasses.fields(cls.Config)} - {"name"} <= documented


def test_unknown_key_is_one_clear_error() -> None:
    with pytest.raises(JtError, match="unknown key"):
        build_config(BDSSearcher.Config, {"name": "bds", "n_explore": 3})


def test_plugin_modules_import_nothing_heavy() -> None:
    code = (
        "import sys, jt_searchers.bds, jt_searchers.rmoo, jt_searchers.bsoo, jt_searchers.random_search, "
        "jt_tasks.strategy_landscape, jt_tasks.zdt\n"
        "heavy = [m for m in ('torch', 'pybullet', 'mlflow', 'numba', 'sklearn', 'cma', 'moocore') if m in sys.modules]\n"
        "print(','.join(heavy))"
    )
    env = {"PYTHONPATH": f"{ROOT}:{ROOT / 'plugins'}", "PATH": "/usr/bin:/bin"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.strip() == ""
