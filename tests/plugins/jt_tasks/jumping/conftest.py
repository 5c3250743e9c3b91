"""Shared fixtures: a high-jump env (raw actions, dense SPD) and the simulator entry point.

Until the lead registers ``jt.simulators: bullet``, the fixture puts a temporary dist-info with
the needed entry points on ``sys.path`` (a real importlib.metadata entry point, no mock).
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

EPS = """[jt.simulators]
bullet = jt_bullet.simulator:BulletSimulator

[jt.tasks]
highjump = jt_tasks.jumping.task:HighJumpTask
obstacle = jt_tasks.jumping.task:ObstacleTask
longjump = jt_tasks.jumping.task:LongJumpTask
"""


@pytest.fixture(scope="session", autouse=True)
def _entry_points(tmp_path_factory):
    from toolkit import plugins

    missing = "bullet" not in plugins.names("sim") or "highjump" not in plugins.names("task")
    if missing:
        root = tmp_path_factory.mktemp("eps")
        d = root / "jt_jumping_test-0.0.dist-info"
        d.mkdir()
        (d / "METADATA").write_text("Metadata-Version: 2.1\nName: jt-jumping-test\nVersion: 0.0\n")
        (d / "entry_points.txt").write_text(EPS)
        sys.path.append(str(root))
        plugins.refresh()
    yield


TERMS = {"task_complete": {}, "root_rotation": {}, "safety": {}, "naturalness": {}}


def make_spec(**kw):
    from jt_tasks.jumping.env import EnvSpec

    base = dict(features={"alpha": -0.05, "omega_x": -3.0, "omega_z": 1.0, "v_z": -2.4},
                sim={"spd": {"name": "df"}}, action={"name": "raw"}, reward_terms=dict(TERMS),
                v_y=None)  # the run clip's own take-off speed, as these tests were written for
    base.update(kw)
    return EnvSpec(**base)


@pytest.fixture
def env():
    from jt_tasks.jumping.env import JumpEnv

    e = JumpEnv(make_spec(), seed=0)
    yield e
    e.close()
