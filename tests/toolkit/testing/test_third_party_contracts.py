"""A third-party distribution written from docs/writing-a-plugin.md alone (a searcher whose Config
has only ``name`` and ``budget``, and a reward term), installed with pip, passes jt's shipped
contract suites (``toolkit.testing``) and runs through ``jt run`` by config alone."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

PYPROJECT = """\
[build-system]
requires = ["setuptools>=68"]
build-backend = "setuptools.build_meta"

[project]
name = "jt-tp-plugin"
version = "0.0.1"

[project.entry-points."jt.searchers"]
tp_random = "jt_tp.searcher:TPRandom"

[project.entry-points."jt.rewards"]
tp_upright = "jt_tp.reward:TPUpright"

[project.entry-points."jt.config"]
jt_tp = "jt_tp.conf"

[tool.setuptools]
packages = ["jt_tp", "jt_tp.conf", "jt_tp.conf.search"]

[tool.setuptools.package-data]
"jt_tp.conf.search" = ["*.yaml"]
"""

SEARCHER = '''\
import dataclasses

import numpy as np

from toolkit.interfaces import Searcher


class TPRandom(Searcher):
    """Uniform random points, one at a time (third-party test plugin)."""

    @dataclasses.dataclass
    class Config:
        name: str = "tp_random"
        budget: int = 6

    def __init__(self, problem, cfg, seed):
        super().__init__(problem, cfg, seed)
        self.budget = int(cfg["budget"]) if cfg is not None and "budget" in cfg else 6
        self.rng = np.random.default_rng(seed)
        self.asked, self.told = [], 0

    def ask(self, n):
        space = self.problem.space
        k = min(n, self.budget - len(self.asked))
        if k <= 0:
            return np.zeros((0, space.dim))
        X = np.array(space.lows) + self.rng.random((k, space.dim)) * (np.array(space.highs) - np.array(space.lows))
        self.asked.extend(X)
        return X

    def tell(self, points, results):
        expected = np.array(self.asked[self.told:self.told + len(points)])
        if expected.shape != np.shape(points) or not np.allclose(expected, points):
            raise ValueError("tell: points it did not ask")
        self.told += len(points)

    def finished(self):
        return self.told >= self.budget

    def summary(self):
        return {"points": np.array(self.asked)}
'''

REWARD = '''\
import dataclasses

from toolkit.config import config_of
from toolkit.interfaces import RewardTerm


class TPUpright(RewardTerm):
    """exp(-scale * tilt): 1 when upright (third-party test plugin)."""

    @dataclasses.dataclass
    class Config:
        name: str = "tp_upright"
        scale: float = 2.0

    def __init__(self, cfg=None):
        super().__init__(cfg)
        self.params = config_of(self.Config, cfg, "reward=tp_upright")

    @classmethod
    def needs(cls, params):
        return {"tilt"}  # the record key it reads (checked against a task's record_keys)

    def __call__(self, record):
        import math

        return math.exp(-self.params.scale * abs(float(record["tilt"])))
'''

TESTS = '''\
import math

from jt_tp.reward import TPUpright
from jt_tp.searcher import TPRandom
from toolkit.testing.reward import RewardTermContract
from toolkit.testing.searcher import SearcherContract


class TestTPRandom(SearcherContract):
    searcher_cls, cfg = TPRandom, {"name": "tp_random", "budget": 6}

    def make_task(self):
        from toolkit import plugins
        return plugins.load("task", "strategy_landscape")({"task": {}})


class TestTPUpright(RewardTermContract):
    cls, entry = TPUpright, "tp_upright"
    record, required = {"tilt": 0.25}, ("tilt",)
    cases = [({}, {"tilt": 0.5}, math.exp(-1.0)), ({"scale": 1.0}, {"tilt": -2.0}, math.exp(-2.0))]
'''


@pytest.fixture(scope="module")
def tp_plugin(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """(site dir it is installed in, its tests folder)."""
    src = tmp_path_factory.mktemp("tp_src")
    pkg = src / "jt_tp"
    (pkg / "conf" / "search").mkdir(parents=True)
    (src / "pyproject.toml").write_text(PYPROJECT)
    for path, text in ((pkg / "__init__.py", ""), (pkg / "conf" / "__init__.py", ""),
                       (pkg / "conf" / "search" / "__init__.py", ""),
                       (pkg / "conf" / "search" / "tp_random.yaml", "name: tp_random\n"),
                       (pkg / "searcher.py", SEARCHER), (pkg / "reward.py", REWARD)):
        path.write_text(text)
    site = tmp_path_factory.mktemp("tp_site")
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--no-build-isolation", "-q",
                    "--disable-pip-version-check", "--target", str(site), str(src)],
                   check=True, capture_output=True)
    tests = tmp_path_factory.mktemp("tp_tests")
    (tests / "test_tp.py").write_text(TESTS)
    return site, tests


def _env(site: Path) -> dict[str, str]:
    env = dict(os.environ)
    env.pop("JT_STORE", None)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(site), env.get("PYTHONPATH", "")) if p)
    return env


def test_the_shipped_suites_pass_on_a_third_party_plugin(tp_plugin):
    site, tests = tp_plugin
    out = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(tests)],
                         capture_output=True, text=True, env=_env(site), cwd=tests, timeout=600)
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-2000:]
    assert re.search(r"\b(1[0-9]|[2-9][0-9]) passed", out.stdout), out.stdout[-1000:]
    assert "failed" not in out.stdout


def test_a_searcher_without_batch_runs_by_config_alone(tp_plugin, tmp_path):
    site, _ = tp_plugin
    out = subprocess.run([sys.executable, "-m", "toolkit.cli", "run", "task=strategy_landscape",
                          "search=tp_random", "experiment=smoke", f"store={tmp_path / 'store'}"],
                         capture_output=True, text=True, env=_env(site), timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    assert re.search(r"run [0-9a-f]{32} FINISHED", out.stdout), out.stdout[-2000:]
    assert "[10/10]" in out.stderr  # the smoke preset's budget, asked one point at a time
