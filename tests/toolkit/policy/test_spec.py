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


def test_spec_of_copies_shared_fields_and_takes_derived_ones():
    from toolkit.policy.spec import default_of, spec_of

    @dataclasses.dataclass
    class Spec:
        a: float = default_of(_Config, "a")
        b: list = default_of(_Config, "b")
        resolved: Optional[str] = None

    assert Spec().a == 1.0 and Spec().b == [1, 2] and Spec().b is not Spec().b
    params = _Config(a=3.0, b=[5])
    spec = spec_of(Spec, params, resolved="r")
    assert (spec.a, spec.b, spec.resolved) == (3.0, [5], "r")
    spec.b.append(6)
    assert params.b == [5]  # a deep copy: the spec is the env's own plain data
    assert spec_of(Spec, params, a=7.0).a == 7.0  # derived overrides a copy
    with pytest.raises(TypeError, match="no field"):
        spec_of(Spec, params, only_config="y")


def test_spacetime_spec_defaults_are_its_configs():
    """Every field SpacetimeSpec shares with SpacetimeConfig has the Config's default (a restated
    default that differs fails here)."""
    from toolkit.policy.spec import shared_fields
    from jt_tasks.spacetime.config import SpacetimeConfig
    from jt_tasks.spacetime.env import SpacetimeSpec

    shared = shared_fields(SpacetimeSpec, SpacetimeConfig)
    assert {"clip", "heading_axis", "cycle_turn", "root_orientation", "time_limit", "style", "mix"} <= set(shared)
    spec, cfg = SpacetimeSpec(), SpacetimeConfig()
    derived = {"widths", "width_table"}  # resolved by the task (bound widths per channel)
    for name in set(shared) - derived:
        assert getattr(spec, name) == getattr(cfg, name), name


def test_every_user_value_reaches_the_spacetime_spec():
    """A non-default value of each shared task.* field arrives in the env's spec unchanged."""
    from toolkit import plugins
    from toolkit.config import compose

    from toolkit.policy.spec import shared_fields
    from jt_tasks.spacetime.config import SpacetimeConfig
    from jt_tasks.spacetime.env import SpacetimeSpec

    values = {"clip": "walk", "loop": False, "ground_clearance": 0.002, "cycle_turn": False, "straighten": True,
              "root_orientation": "heading", "velocities": "links", "ffc_lead": 1.0, "ffc_velocity": True, "termination": "contact",
              "time_limit": 5.0, "hold_s": 0.25, "init_phase": 0.5, "eval_time_limit": 3.0, "mix": 0.5,
              "style": [{"name": "energy"}], "heading_axis": "z"}
    assert set(values) == set(shared_fields(SpacetimeSpec, SpacetimeConfig)) - {"widths", "width_table"}
    style = values.pop("style")
    cfg = compose(["task=spacetime", *(f"task.{k}={v}" for k, v in values.items()), "task.style=[{name: energy}]"])
    spec = plugins.load("task", "spacetime")(cfg).env_spec({})
    for k, v in values.items():
        assert getattr(spec, k) == v, k
    assert spec.style == style


def test_getup_spec_defaults_are_its_configs():
    """The same for GetupSpec and GetupConfig; curves and terrain are resolved by the task (the
    Config names the curves, the spec holds them; the spec's {} terrain is flat ground)."""
    from jt_tasks.getup.config import GetupConfig
    from jt_tasks.getup.env import GetupSpec
    from toolkit.policy.spec import shared_fields

    shared = set(shared_fields(GetupSpec, GetupConfig)) - {"curves", "terrain"}
    assert {"t_stand", "natural_terms", "heightmap_spacing", "success_window"} <= shared
    spec, cfg = GetupSpec(), GetupConfig()
    for name in shared:
        assert getattr(spec, name) == getattr(cfg, name), name


def test_runup_spec_defaults_are_its_configs():
    """The same for RunupSpec and RunupConfig; target is the task's resolved take-off features."""
    from toolkit.policy.spec import shared_fields
    from jt_tasks.runup.env import RunupSpec
    from jt_tasks.runup.config import RunupConfig

    shared = set(shared_fields(RunupSpec, RunupConfig)) - {"target"}
    assert {"kind", "omega_y", "clip", "w_goal", "goal_steps"} <= shared
    spec, cfg = RunupSpec(), RunupConfig()
    for name in shared:
        assert getattr(spec, name) == getattr(cfg, name), name


def test_jump_env_spec_defaults_are_its_configs():
    """The same for the jumps' EnvSpec and JumpConfig (v_y was None in the spec, 2.06 m/s in the
    Config); policy_features is the task's resolved Stage-2 list."""
    from jt_tasks.jumping.config import JumpConfig
    from jt_tasks.jumping.env import EnvSpec
    from toolkit.policy.spec import shared_fields

    shared = set(shared_fields(EnvSpec, JumpConfig)) - {"policy_features"}
    assert {"clip", "foot", "omega_y", "v_y", "time_limit", "safe_margin", "check_every"} <= shared
    spec, cfg = EnvSpec(), JumpConfig()
    for name in shared:
        assert getattr(spec, name) == getattr(cfg, name), name
    assert spec.v_y == 2.06
