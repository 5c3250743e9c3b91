"""energy and volume (002 §3.3 eqs 4-5), style terms of task=spacetime."""

from __future__ import annotations

import math

import numpy as np
import pytest

from jt_rewards.style import Energy, Volume, hull_volume, kinetic_energy
from toolkit.testing.reward import RewardTermContract
from toolkit.errors import JtError

CUBE = np.array([[x, y, z] for x in (0, 0.5) for y in (0, 0.6) for z in (0, 0.4)], dtype=float)  # 0.12 m³
RECORD = {"kinetic_energy": 60.0, "joint_pos": CUBE, "link_vel": np.full((15, 3), 0.8), "masses": np.full(15, 3.0)}


class TestEnergy(RewardTermContract):
    # kinetic_energy, or link_vel and masses: no single key the term cannot do without
    cls, entry, record, required = Energy, "energy", RECORD, ()
    cases = [({}, {"kinetic_energy": 60.0}, 0.5), ({}, {"kinetic_energy": 10.0}, 1.0),
             ({}, {"kinetic_energy": 120.0}, 0.0), ({"mode": "increase"}, {"kinetic_energy": 40.0}, 0.25),
             ({"e_min": 0.0, "e_max": 10.0}, {"kinetic_energy": 2.5}, 0.75)]


class TestVolume(RewardTermContract):
    cls, entry, record, required = Volume, "volume", RECORD, ("joint_pos",)
    cases = [({}, {"joint_pos": CUBE}, math.exp(-1.0)), ({"mode": "increase"}, {"joint_pos": CUBE}, 1 - math.exp(-1.0)),
             ({}, {"joint_pos": CUBE[:4]}, 1.0),  # a flat square: no volume
             ({"alpha": 0.06}, {"joint_pos": CUBE}, math.exp(-2.0))]


def test_energy_removes_only_the_horizontal_com_motion():
    m = np.array([2.0, 3.0])
    same = np.array([[1.0, 0.0, 2.0], [1.0, 0.0, 2.0]])  # the whole body translating horizontally
    assert kinetic_energy(same, m) == pytest.approx(0.0, abs=1e-12)
    up = np.array([[0.0, 2.0, 0.0], [0.0, 2.0, 0.0]])  # vertical motion counts
    assert kinetic_energy(up, m) == pytest.approx(0.5 * 5.0 * 4.0)
    apart = np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])
    assert kinetic_energy(apart, m, rotational=1.5) == pytest.approx(2.5 - 0.5 * 1.0 / 5.0 + 1.5)
    assert Energy()({"link_vel": up, "masses": m}) == pytest.approx(1.0)


def test_hull_volume_of_a_box_and_bad_modes():
    assert hull_volume(CUBE) == pytest.approx(0.12)
    assert hull_volume(CUBE[:3]) == 0.0
    for cls in (Energy, Volume):
        with pytest.raises(JtError, match="decrease or increase"):
            cls({"mode": "more"})
    with pytest.raises(JtError):
        Energy({"e_min": 100.0, "e_max": 20.0})


def test_energy_without_either_source_names_both():
    with pytest.raises(KeyError, match="kinetic_energy.*link_vel"):
        Energy()({"joint_pos": CUBE})
