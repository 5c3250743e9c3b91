"""``toolkit.policy.spec``: an env's spec derived from its task's Config, one default per value."""

from __future__ import annotations

import dataclasses
from typing import Optional

import pytest


@dataclasses.dataclass
class _Config:
    a: float = 1.0
    b: list = dataclasses.field(default_factory=lambda: [1, 2])
    only_config: str = "x"


def test_spec_of_copies_the_configs_fields_and_takes_derived_ones():
    from toolkit.policy.spec import spec_of

    @dataclasses.dataclass
    class Spec(_Config):
        resolved: Optional[str] = None

    assert Spec().a == 1.0 and Spec().b == [1, 2] and Spec().b is not Spec().b
    params = _Config(a=3.0, b=[5], only_config="y")
    spec = spec_of(Spec, params, resolved="r")
    assert (spec.a, spec.b, spec.only_config, spec.resolved) == (3.0, [5], "y", "r")
    spec.b.append(6)
    assert params.b == [5]  # a deep copy: the spec is the env's own plain data
    assert spec_of(Spec, params, a=7.0).a == 7.0  # derived overrides a copy
    with pytest.raises(TypeError, match="no field"):
        spec_of(Spec, params, nosuch="y")


def _specs():
    from jt_tasks.getup.config import GetupConfig
    from jt_tasks.getup.env import GetupSpec
    from jt_tasks.jumping.config import JumpConfig
    from jt_tasks.jumping.env import EnvSpec
    from jt_tasks.runup.config import RunupConfig
    from jt_tasks.runup.env import RunupSpec
    from jt_tasks.spacetime.config import SpacetimeConfig
    from jt_tasks.spacetime.env import SpacetimeSpec

    #: (spec, config, the config fields the spec holds resolved: the Config names them, the task resolves them)
    return [(GetupSpec, GetupConfig, {"curves", "terrain"}), (EnvSpec, JumpConfig, {"policy_features"}),
            (RunupSpec, RunupConfig, {"target"}), (SpacetimeSpec, SpacetimeConfig, {"widths", "width_table"})]


@pytest.mark.parametrize("k", range(4))
def test_each_setting_is_declared_once_in_the_tasks_config(k):
    """Every policy task's env spec is its Config plus resolved values: each task.* field reaches
    the env with no second declaration (issue 54: 51 restated defaults across four specs), and the
    spec redeclares a Config field only to hold its resolved value."""
    spec_cls, config_cls, resolved = _specs()[k]
    assert issubclass(spec_cls, config_cls)
    own = set(spec_cls.__dict__.get("__annotations__", {}))
    assert own & {f.name for f in dataclasses.fields(config_cls)} == resolved
    spec, cfg = spec_cls(), config_cls()
    for f in dataclasses.fields(config_cls):
        if f.name not in resolved:
            assert getattr(spec, f.name) == getattr(cfg, f.name), f.name


def test_a_new_config_field_reaches_the_env_spec_with_no_other_edit():
    """What docs/writing-a-plugin.md promises: a field added to a task's Config (here by a
    subclass, as an edit would) is in its spec, copied from the task's parameters."""
    from jt_tasks.getup.config import GetupConfig
    from toolkit.policy.spec import spec_of

    @dataclasses.dataclass
    class Extended(GetupConfig):
        new_setting: float = 0.25

    @dataclasses.dataclass
    class ExtendedSpec(Extended):
        sim: dict = dataclasses.field(default_factory=dict)

    assert spec_of(ExtendedSpec, Extended(new_setting=0.75), sim={}).new_setting == 0.75


def test_every_user_value_reaches_the_spacetime_spec():
    """A non-default value of each shared task.* field arrives in the env's spec unchanged."""
    from toolkit import plugins
    from toolkit.config import compose

    from toolkit.policy.spec import shared_fields
    from jt_tasks.spacetime.config import SpacetimeConfig
    from jt_tasks.spacetime.env import SpacetimeSpec

    values = {"clip": "walk", "loop": True, "ground_clearance": 0.002, "cycle_turn": False, "straighten": True,
              "root_orientation": "heading", "velocities": "links", "ffc_lead": 1.0, "ffc_velocity": True, "termination": "contact",
              "time_limit": 5.0, "hold_s": 0.25, "init_phase": 0.5, "eval_time_limit": 3.0, "mix": 0.5,
              "style": [{"name": "energy"}], "heading_axis": "z"}
    assert set(values) <= set(shared_fields(SpacetimeSpec, SpacetimeConfig)) - {"widths", "width_table"}
    style = values.pop("style")
    cfg = compose(["task=spacetime", *(f"task.{k}={v}" for k, v in values.items()), "task.style=[{name: energy}]"])
    spec = plugins.load("task", "spacetime")(cfg).env_spec({})
    for k, v in values.items():
        assert getattr(spec, k) == v, k
    assert spec.style == style
