"""task_complete, root_rotation, safety, naturalness (000 §6.1.2 eqs 2, 16; §4.2 eq 4)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from jt_rewards.terms import Naturalness, RootRotation, Safety, TaskComplete, mean_speed
from toolkit.testing.reward import RewardTermContract

RECORD = {"success": True, "root_ang_vel_mean": 3.0, "head_first_landing": False, "naturalness": 0.8}


class TestTaskComplete(RewardTermContract):
    cls, entry, record, required = TaskComplete, "task_complete", RECORD, ("success",)
    cases = [({}, {"success": True}, 1.0), ({}, {"success": False}, 0.0),
             ({}, {"success": 1}, 1.0), ({}, {"success": 0.0}, 0.0),
             ({"key": "cleared"}, {"cleared": np.bool_(True)}, 1.0)]


class TestRootRotation(RewardTermContract):
    cls, entry, record, required = RootRotation, "root_rotation", RECORD, ("root_ang_vel_mean",)
    cases = [({}, {"root_ang_vel_mean": 0.0}, 1.0),
             ({}, {"root_ang_vel_mean": 5.0}, math.exp(-0.1)),     # exp(-0.02·5)
             ({}, {"root_ang_vel_mean": 50.0}, math.exp(-1.0)),
             ({"k": 0.1}, {"root_ang_vel_mean": 10.0}, math.exp(-1.0)),
             # per-step velocities: mean of the norms (3-4-5 and 0-0-1 → 3), not norm of the mean
             ({}, {"root_ang_vel_mean": [[3.0, 4.0, 0.0], [0.0, 0.0, 1.0]]}, math.exp(-0.02 * 3.0))]

    def test_magnitude_is_averaged_not_the_vector(self):
        spin = np.array([[0.0, 4.0, 0.0], [0.0, -4.0, 0.0]])  # mean vector 0, mean speed 4
        assert mean_speed(spin) == 4.0
        assert RootRotation()({"root_ang_vel_mean": spin}) == pytest.approx(math.exp(-0.08))

    def test_bad_shapes_and_values_rejected(self):
        with pytest.raises(ValueError):
            RootRotation()({"root_ang_vel_mean": [[1.0, 2.0]]})
        with pytest.raises(ValueError):
            RootRotation()({"root_ang_vel_mean": float("nan")})
        with pytest.raises(ValueError):
            RootRotation()({"root_ang_vel_mean": -1.0})


class TestSafety(RewardTermContract):
    cls, entry, record, required = Safety, "safety", RECORD, ("head_first_landing",)
    cases = [({}, {"head_first_landing": True}, 0.7), ({}, {"head_first_landing": False}, 1.0),
             ({}, {"head_first_landing": 1.0}, 0.7), ({"factor": 0.5}, {"head_first_landing": 1}, 0.5)]


class TestNaturalness(RewardTermContract):
    cls, entry, record, required = Naturalness, "naturalness", RECORD, ("naturalness",)
    cases = [({}, {"naturalness": 1.0}, 1.0), ({}, {"naturalness": 0.0}, 0.0),
             ({}, {"naturalness": 0.3125}, 0.3125), ({"key": "penalty"}, {"penalty": 0.5}, 0.5)]

    def test_passes_through_the_eq4_value(self):
        # eq 4 with an episode-mean offset L1 norm of 24 and c_offset = 48: 1 - (24/48)^2 = 0.75
        eq4 = 1.0 - min(max((24.0 / 48.0) ** 2, 0.0), 1.0)
        assert Naturalness()({"naturalness": eq4}) == 0.75

    def test_outside_unit_interval_rejected(self):
        for bad in (1.5, -0.2, float("inf")):
            with pytest.raises(ValueError):
                Naturalness()({"naturalness": bad})


def test_wrong_config_type_is_one_clear_error():
    from toolkit.errors import JtError

    with pytest.raises(JtError, match=r"reward term \w+: k: .*fast"):
        RootRotation({"k": "fast"})
    assert RootRotation({"k": 1}).params.k == 1.0 and isinstance(RootRotation({"k": 1}).params.k, float)
