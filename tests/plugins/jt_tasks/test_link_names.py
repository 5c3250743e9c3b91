"""Tasks name the humanoid's links; the simulator resolves each name to the PyBullet index the
task constant held before (issue 27), so a renamed link fails here, loudly, not in a rollout."""

from __future__ import annotations

import pytest

from jt_tasks.getup import features as getup_features
from jt_tasks.getup import terrain as getup_terrain
from jt_tasks.jumping import env as jumping_env
from jt_tasks.runup import reference as runup_reference
from jt_tasks.spacetime import reference as spacetime_reference
from jt_tasks.takeoff import state as takeoff_state

#: (where, name) -> the index the constant held when it was an index
RECORDED = [
    ("takeoff.state.FOOT_LINKS['right']", takeoff_state.FOOT_LINKS["right"], 5),
    ("takeoff.state.FOOT_LINKS['left']", takeoff_state.FOOT_LINKS["left"], 11),
    ("jumping.env.HEAD", jumping_env.HEAD, 2),
    ("getup.features.NECK", getup_features.NECK, 2),
    ("getup.features.RIGHT_HIP", getup_features.RIGHT_HIP, 3),
    ("getup.features.LEFT_HIP", getup_features.LEFT_HIP, 9),
    ("getup.features.HEAD", getup_features.HEAD, 2),
    ("getup.terrain.FEET[0] foot", getup_terrain.FEET[0][1], 5),
    ("getup.terrain.FEET[0] parent", getup_terrain.FEET[0][2], 4),
    ("getup.terrain.FEET[1] foot", getup_terrain.FEET[1][1], 11),
    ("getup.terrain.FEET[1] parent", getup_terrain.FEET[1][2], 10),
] + [(f"runup.reference.END_EFFECTORS[{i}]", n, k)
     for i, (n, k) in enumerate(zip(runup_reference.END_EFFECTORS, (5, 11, 8, 14)))] \
  + [(f"spacetime.reference.END_EFFECTORS[{i}]", n, k)
     for i, (n, k) in enumerate(zip(spacetime_reference.END_EFFECTORS, (5, 8, 11, 14)))]


@pytest.fixture(scope="module")
def sim():
    """The simulator plugin of the default configuration (the humanoid)."""
    from omegaconf import OmegaConf

    from toolkit import plugins
    from toolkit.config import compose

    cfg = compose([])
    s = plugins.load("sim", str(cfg.sim.name))(OmegaConf.create(
        {"sim": cfg.sim, "character": cfg.character, "spd": cfg.spd}))
    yield s
    s.close()


@pytest.mark.parametrize("where, name, index", RECORDED, ids=[r[0] for r in RECORDED])
def test_each_link_name_resolves_to_the_index_it_replaced(sim, where, name, index):
    assert isinstance(name, str), where
    assert sim.link_index(name) == index, where


def test_the_humanoid_skeletons_link_order_is_the_simulators_link_indices(sim):
    """Mocap code resolves the same names through ``Skeleton.link_index`` (forward kinematics
    rows, the kinematic body, spacetime's allowed contacts): both orders must agree."""
    from toolkit.motion.skeletons import HUMANOID

    assert [sim.link_index(n) for n in HUMANOID.links] == list(range(len(HUMANOID.links)))
    assert len(HUMANOID.links) == sim.n_links
    assert spacetime_reference.end_effector_links(HUMANOID) == spacetime_reference.end_effector_links(sim)
