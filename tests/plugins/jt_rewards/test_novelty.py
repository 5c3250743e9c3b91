"""novelty: clip(min_i d(f, f_i) / d_threshold, 0.01, 1) (000 eq 12, 001 eq 3.12)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from toolkit.errors import JtError

from jt_rewards.distances import angle, quat, resolve, rotvec
from jt_rewards.novelty import Novelty
from toolkit.testing.reward import RewardTermContract
from toolkit.motion.rotations import quat_angle, quat_from_expmap

HALF_PI = math.pi / 2


class TestNovelty(RewardTermContract):
    cls, entry, required = Novelty, "novelty", ("feature",)
    record = {"feature": [0.3, 0.0, 0.0], "policy_features": [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]}
    cases = [
        # min distance 0.3 → 0.3 / (π/2)
        ({}, record, 0.3 / HALF_PI),
        # far from every previous policy: clipped to 1
        ({}, {"feature": [5.0, 0.0], "policy_features": [[0.0, 0.0]]}, 1.0),
        # identical to a previous policy: clipped to the 0.01 floor
        ({}, {"feature": [1.0, 2.0], "policy_features": [[1.0, 2.0], [9.0, 9.0]]}, 0.01),
        # tiny but non-zero distance: still the floor
        ({}, {"feature": [0.001], "policy_features": [[0.0]]}, 0.01),
        # no previous policy: min over the empty set is +inf → 1
        ({}, {"feature": [0.2, 0.1], "policy_features": []}, 1.0),
        ({}, {"feature": [0.2, 0.1]}, 1.0),  # no key and an empty config list
        ({"d_threshold": 2.0}, {"feature": [3.0, 4.0], "policy_features": [[0.0, 0.0], [3.0, 5.0]]}, 0.5),
        # the config's policy features stand in when the record carries none
        ({"policy_features": [[0.0, 0.5]]}, {"feature": [0.0, 0.0]}, 0.5 / HALF_PI),
    ]

    def test_wrap_around_angle_distance(self):
        term = Novelty({"distance": "angle"})
        # π − 0.1 and −π + 0.1 are 0.2 apart, not 2π − 0.2
        rec = {"feature": [math.pi - 0.1], "policy_features": [[-math.pi + 0.1]]}
        assert term(rec) == pytest.approx(0.2 / HALF_PI)
        assert Novelty()(rec) == 1.0  # Euclidean sees 2π − 0.2 and clips
        assert angle(np.array([0.0, 3.0]), np.array([[2 * math.pi, 3.0 + 4 * math.pi]]))[0] == pytest.approx(0.0, abs=1e-12)

    def test_quaternion_sign_does_not_matter(self):
        q = quat_from_expmap([0.1, -0.4, 0.3])
        r = quat_from_expmap([0.5, 0.2, -0.1])
        expected = float(quat_angle(q, r))  # toolkit's rotation angle as the reference
        d = quat(q, np.stack([r, -r]))
        assert d == pytest.approx([expected, expected], abs=1e-12)
        term = Novelty({"distance": "quat"})
        assert term({"feature": q, "policy_features": [-q]}) == 0.01  # same rotation
        assert term({"feature": -q, "policy_features": [r]}) == pytest.approx(min(expected / HALF_PI, 1.0))

    def test_quaternion_distance_is_the_rotation_angle(self):
        # rotations about one axis by 0.2 and 1.0 rad: 0.8 rad apart; a half turn: π
        a = quat_from_expmap([0.0, 0.2, 0.0])
        b = quat_from_expmap([0.0, 1.0, 0.0])
        assert quat(a, b[None])[0] == pytest.approx(0.8, abs=1e-12)
        assert quat(quat_from_expmap([0, 0, 0]), quat_from_expmap([math.pi, 0, 0])[None])[0] == pytest.approx(math.pi)
        assert quat(a, a[None])[0] == 0.0  # exact at zero (no arccos round-off)
        with pytest.raises(ValueError):
            quat(np.zeros(3), np.zeros((1, 3)))

    def test_rotvec_matches_quat_and_wraps_at_pi(self):
        v, w = np.array([0.3, 0.2, -0.9]), np.array([-1.0, 0.4, 0.2])
        assert rotvec(v, w[None])[0] == pytest.approx(float(quat_angle(quat_from_expmap(v), quat_from_expmap(w))), abs=1e-12)
        # a turn of π − ε about x and of −(π − ε) about x are 2ε apart
        eps = 0.05
        assert rotvec(np.array([math.pi - eps, 0, 0]), np.array([[-(math.pi - eps), 0, 0]]))[0] == pytest.approx(2 * eps)

    def test_several_quaternions_combine_as_a_norm(self):
        i = quat_from_expmap([0.0, 0.0, 0.0])
        f = np.concatenate([i, i])
        g = np.concatenate([quat_from_expmap([0.3, 0, 0]), quat_from_expmap([0, 0.4, 0])])
        assert quat(f, g[None])[0] == pytest.approx(0.5)

    def test_min_over_policies_and_shapes(self):
        term = Novelty()
        assert term.min_distance([0.0, 0.0], [[3.0, 4.0], [0.0, 1.0]]) == 1.0
        assert term.min_distance([0.0, 0.0], np.zeros((0, 2))) == math.inf
        assert term.min_distance([2.0], [0.0, 1.5]) == 0.5  # a 1-D feature, a flat list of f_i
        with pytest.raises(ValueError, match="disagree"):
            term.min_distance([0.0, 0.0], [[1.0, 2.0, 3.0]])

    def test_bad_config_rejected(self):
        with pytest.raises(ValueError, match="unknown feature distance"):
            Novelty({"distance": "manhattan"})
        with pytest.raises(JtError):
            Novelty({"d_threshold": 0.0})
        assert resolve("quat") is quat

    def test_paper_defaults(self):
        p = Novelty().params
        assert (p.d_threshold, p.low, p.high) == (HALF_PI, 0.01, 1.0)
