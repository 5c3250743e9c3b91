"""action=pvae: target = D_pose(latent) + offset; naturalness 000 eq 4."""

import numpy as np
import pytest

from filter_contract import FilterOption
from toolkit.testing.action import ActionSpaceContract
from jt_actions.base import naturalness
from jt_actions.pvae import PVAEActionSpace
from toolkit.errors import JtError
from toolkit.motion import HUMANOID
from toolkit.priors.io import load_prior


class TestPVAE(ActionSpaceContract, FilterOption):
    @pytest.fixture(autouse=True)
    def _priors(self, action_priors):
        self.priors = action_priors

    def make(self):
        return PVAEActionSpace({"name": "pvae", "prior": str(self.priors["pvae"])}, HUMANOID)

    def test_layout_and_composite_targets(self):
        space = self.make()
        prior = load_prior(self.priors["pvae"])
        k = prior.latent_dim
        assert space.dim == k + 28
        low, high = space.bounds()
        assert np.all(high[:k] == 3.0) and np.all(high[k:] == 1.0) and np.all(low == -high)
        rng = np.random.default_rng(0)
        a = np.concatenate([rng.uniform(-1, 1, k), np.zeros(28)])
        natural = prior.decode_targets(prior.latent_from_action(a[:k]))
        from toolkit.priors.limits import limit_targets

        np.testing.assert_allclose(space.targets(a), limit_targets(HUMANOID, natural), atol=1e-12)
        a[k + 0] = 0.05  # an offset on the chest's first exp-map component adds to the decoded target
        assert space.targets(a)[0] == pytest.approx(limit_targets(HUMANOID, natural)[0] + 0.05)

    def test_naturalness_hand_computed(self):
        space = self.make()
        k = space.latent_dim
        assert space.c_offset == 15.0
        for l1, expected in ((0.0, 1.0), (7.5, 0.75), (15.0, 0.0), (30.0, 0.0), (3.0, 0.96)):
            a = np.zeros(space.dim)
            a[k:] = l1 / 28.0
            space.targets(a)
            assert space.penalty() == pytest.approx(expected)
        space.set_c_offset(48.0)  # 000 §6.1.2: the curriculum's starting value
        assert space.penalty() == pytest.approx(1 - (3.0 / 48.0) ** 2)
        with pytest.raises(ValueError):
            space.set_c_offset(0.0)
        assert naturalness(5.0, 10.0) == pytest.approx(0.75)

    def test_episode_average_for_sparse_rewards(self):
        space = PVAEActionSpace({"prior": str(self.priors["pvae"]), "episode_average": True})
        k = space.latent_dim
        for n in (3, 9):  # ||a_offset||_1 = 3, then 9: episode mean 6
            a = np.zeros(space.dim)
            a[k : k + n] = 1.0
            space.targets(a)
        assert space.offset_norm() == pytest.approx(6.0)
        assert space.penalty() == pytest.approx(1 - (6.0 / 15.0) ** 2)
        space.reset()
        assert space.offset_norm() == 0.0 and space.penalty() == 1.0

    def test_needs_a_prior_of_its_kind(self):
        with pytest.raises(JtError) as e:
            PVAEActionSpace({"name": "pvae"})
        assert "jt run task=pose_prior action=pvae" in str(e.value)
        with pytest.raises(JtError) as e:
            PVAEActionSpace({"prior": str(self.priors["cvae"])})
        assert "cvae prior" in str(e.value)
        with pytest.raises(JtError):
            PVAEActionSpace({"prior": str(self.priors["pvae"]), "bogus": 1})
