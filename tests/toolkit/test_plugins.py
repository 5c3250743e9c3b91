"""Plugin discovery: every kind has its group, built-ins and third-party plugins alike."""

import subprocess
import sys

import pytest

from toolkit import plugins
from toolkit.errors import UnknownPlugin
from toolkit.interfaces import Executor, Searcher, Task

EXPECTED_BUILTINS = {
    "executor": {"local", "ray"},
    "search": {"single", "random", "bds", "rmoo", "bsoo"},
    "spd": {"maba", "df", "sf", "pcg", "bullet", "servo"},
    "action": {"raw", "pvae", "cvae", "ffc_fbc"},
    "reward": {"task_complete", "root_rotation", "safety", "naturalness", "novelty"},
    "curriculum": {"bar_height", "obstacle_width", "terrain"},
    "task": {"strategy_landscape", "zdt1", "pose_prior", "spd_tracking", "standing_jump", "highjump", "obstacle", "longjump"},
    "sim": {"bullet"},
}


def test_every_kind_has_an_entry_point_group():
    assert set(plugins.KINDS) == {"task", "sim", "spd", "action", "reward", "curriculum", "search", "executor"}
    assert all(g.startswith("jt.") for g in plugins.KINDS.values())


@pytest.mark.parametrize("kind", sorted(EXPECTED_BUILTINS))
def test_builtins_discovered_through_entry_points(kind):
    infos = {i.name: i for i in plugins.available(kind)}
    assert EXPECTED_BUILTINS[kind] <= set(infos)
    for name in EXPECTED_BUILTINS[kind]:
        assert infos[name].dist == "jt"
        status, summary = plugins.describe(infos[name])
        assert status == "ok" and summary, (name, summary)


def test_every_builtin_loads_and_implements_its_interface():
    from toolkit.interfaces import ActionSpace, Curriculum, RewardTerm, Simulator, SPDBackend

    base = {"task": Task, "search": Searcher, "executor": Executor, "spd": SPDBackend,
            "action": ActionSpace, "reward": RewardTerm, "curriculum": Curriculum, "sim": Simulator}
    for kind, cls_base in base.items():
        for name in plugins.names(kind):
            info = next(i for i in plugins.available(kind) if i.name == name)
            if info.dist != "jt":
                continue
            assert issubclass(plugins.load(kind, name), cls_base), (kind, name)


def test_unknown_plugin_lists_choices():
    with pytest.raises(UnknownPlugin) as e:
        plugins.load("search", "bdx")
    assert "unknown search 'bdx'; choose one of:" in str(e.value) and "single" in str(e.value)


def test_third_party_plugin_discovered_and_broken_one_reported(example_plugin):
    infos = {i.name: i for i in plugins.available("task")}
    assert infos["quadratic"].dist == "jt-example-plugin"
    assert plugins.describe(infos["quadratic"])[0] == "ok"
    status, reason = plugins.describe(infos["broken_example"])
    assert status == "broken" and "jt_example_missing_dependency" in reason


def test_listing_imports_nothing_heavy():
    code = (
        "import sys\n"
        "from toolkit import plugins\n"
        "for k in plugins.KINDS:\n"
        "    for i in plugins.available(k): plugins.describe(i)\n"
        "heavy = [m for m in ('torch', 'pybullet', 'mlflow', 'sklearn', 'numba') if m in sys.modules]\n"
        "print(','.join(heavy))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "", f"plugin listing imported {out.stdout.strip()}"
