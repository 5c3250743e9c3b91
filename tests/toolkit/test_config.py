"""Composition and validation: typed groups, one-line errors naming the problem."""

import pytest

from toolkit.config import compose, group_options
from toolkit.errors import JtError


def test_compose_types_plugin_groups(example_plugin):
    cfg = compose(["task=quadratic", "task.centre=0.5", "seed=7"])
    assert cfg.task.centre == 0.5 and cfg.seed == 7
    assert cfg.search.name == "single" and cfg.executor.name == "local"
    with pytest.raises(Exception):
        cfg.task.centre = "not a number"  # typed by the plugin's Config


def test_plugin_shipped_preset_applies(example_plugin):
    assert "smoke_quadratic" in group_options("preset")
    cfg = compose(["task=quadratic", "task.sleep=5", "experiment=smoke"])
    assert cfg.profile == "smoke" and cfg.executor.workers == 1
    assert cfg.task.sleep == 5.0  # command line wins over the preset


@pytest.mark.parametrize(
    "overrides, expected",
    [
        (["search=bdx"], "unknown search 'bdx'; choose one of:"),
        (["task=quadratic", "task.centre=abc"], "could not be converted to Float"),
        (["task=quadratic", "task.nope=1"], "unknown key 'task.nope'"),
        (["task=quadratic", "seed=abc"], "seed"),
        (["task=quadratic", "experiment=nah"], "unknown experiment 'nah'; choose one of: default"),
        (["task=quadratic", "task.centre=[1,"], "bad override"),
        (["task=quadratic", "character=robot"], "unknown character 'robot'; choose one of: atlas"),
    ],
)
def test_bad_input_is_one_line(example_plugin, overrides, expected):
    with pytest.raises(JtError) as e:
        compose(overrides)
    msg = str(e.value)
    assert expected in msg and "\n" not in msg, msg


def test_group_of_and_plain_read_any_run_config_shape():
    from types import SimpleNamespace

    from omegaconf import OmegaConf

    from toolkit.config import group_of, plain

    node = OmegaConf.create({"sim": {"name": "bullet", "hz": "${x}"}, "x": 600})
    assert plain(group_of(node, "sim")) == {"name": "bullet", "hz": 600}  # resolved, a plain dict
    assert group_of({"sim": {"name": "b"}}, "sim") == {"name": "b"}
    assert group_of(SimpleNamespace(sim=3), "sim") == 3
    assert group_of(node, "spd") is None and group_of(None, "sim") is None and plain(None) == {}
