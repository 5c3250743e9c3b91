"""standing_jump reaches its planar world through the registry (``sim``) and reports user
mistakes as one-line ``JtError``s."""

from __future__ import annotations

import pytest

from jt_tasks.standing_jump.model import build_body
from jt_tasks.standing_jump.simulate import SimSettings, planar_world, simulate, spd_solver
from toolkit.errors import JtError


def test_the_world_stands_the_character_at_the_origin():
    body = build_body(80.0, 1.60)
    world = planar_world(body, 1.0, 600.0)
    try:
        q, qd = world.joint_states()
        assert q[world.joint_names.index("root_z")] == pytest.approx(body.hip_height + 1e-4)
        assert q[world.joint_names.index("root_x")] == 0.0 and qd == [0.0] * len(qd)
    finally:
        world.close()


def test_bullet_spd_is_a_jt_error():
    with pytest.raises(JtError, match="use maba, df, sf or pcg"):
        spd_solver({"name": "bullet"})
    assert type(spd_solver(None)).__name__ == "MabaBackend"


def test_a_simulator_without_a_planar_world_is_a_jt_error(monkeypatch):
    from toolkit import plugins

    class Plain:  # a simulator plugin class without planar_world
        pass

    monkeypatch.setattr(plugins, "load", lambda kind, name: Plain)
    with pytest.raises(JtError, match="sim=plain has no planar world"):
        simulate({}, SimSettings(sim="plain"))


def test_an_unknown_simulator_is_a_jt_error():
    with pytest.raises(JtError, match="nosuchsim"):
        simulate({}, SimSettings(sim="nosuchsim"))
