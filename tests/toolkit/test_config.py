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


def test_executor_workers_is_the_interface_s_key(monkeypatch):
    """``executor.workers`` is declared by ``Executor.common_keys`` (``ExecutorKeys``): an executor
    whose ``Config`` lacks it still composes under ``experiment=smoke`` and with the key on the
    command line, type- and range-checked, and is built from its own keys only; one that declares
    it keeps it."""
    import dataclasses

    from toolkit import plugins
    from toolkit.interfaces import Executor

    class Serial(Executor):
        """One after the other."""

        @dataclasses.dataclass
        class Config:
            name: str = "local"

        def imap(self, fn, items):
            return enumerate(map(fn, items))

        def actors(self, factory, args):  # pragma: no cover - not called
            raise NotImplementedError

    real = plugins.load
    monkeypatch.setattr(plugins, "load", lambda kind, name: Serial if kind == "executor" else real(kind, name))
    assert "workers" not in compose(["task=zdt1", "experiment=smoke"]).executor  # the preset sets workers: 1
    assert dict(compose(["task=zdt1", "executor.workers=3"]).executor) == {"name": "local"}
    for bad, why in (("abc", "could not be converted to Integer"), ("-2", "a count of workers >= 0")):
        with pytest.raises(JtError, match=why) as e:
            compose(["task=zdt1", f"executor.workers={bad}"])
        assert str(e.value).startswith(f"executor.workers={bad}") and "\n" not in str(e.value)
    monkeypatch.setattr(plugins, "load", real)
    assert compose(["task=zdt1", "executor.workers=3"]).executor.workers == 3  # executor=local declares it


def test_an_experiment_a_task_has_no_preset_for_is_one_line_naming_its_experiments():
    """``task=getup experiment=table1`` (a spacetime preset) would run the task's defaults (the
    paper's 100 M samples) without a word; it is refused, naming the experiments getup has."""
    from toolkit.errors import JtError

    with pytest.raises(JtError, match=r"experiment=table1: task=getup has no preset.*its experiments: default, laptop, paper, quick, smoke") as e:
        compose(["task=getup", "experiment=table1"])
    assert "\n" not in str(e.value)
    assert compose(["task=getup", "experiment=quick"]).profile == "quick"
    assert compose(["task=getup"]).profile == "default"  # no experiment named: the task's defaults


@pytest.mark.parametrize("override", ["character.kp=inf", "agent.policy_lr=nan", "sim.gravity=-inf",
                                      "task.takeoff.v_z=nan", "task.time_scale=nan"])
def test_a_number_that_is_not_finite_is_one_line(override):
    """NaN and ±inf are refused at composition wherever a field does not say otherwise (issue 30)."""
    from toolkit.config import compose
    from toolkit.errors import JtError

    task = "getup" if override.startswith("task.time_scale") else "highjump"
    with pytest.raises(JtError, match=r"must be a finite number"):
        compose([f"task={task}", "experiment=smoke", override])


def test_inf_switches_a_spacetime_bound_off_but_nan_is_refused():
    """task.widths / com_width take .inf (a channel off, 002 §5.3.1's style runs): NONFINITE_OK."""
    from toolkit.config import compose
    from toolkit.errors import JtError

    cfg = compose(["task=spacetime", "experiment=smoke", "preset=style_cartwheel_low_energy"])
    assert cfg.task.widths.orientation == float("inf")
    with pytest.raises(JtError, match=r"task.com_width=nan: must be a number \(not NaN\)"):
        compose(["task=spacetime", "experiment=smoke", "task.com_width=nan"])
