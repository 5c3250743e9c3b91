"""action=cvae: filtered actions (003 §3.4), decode with the condition, naturalness 003 eq 3."""

import numpy as np
import pytest

from filter_contract import FilterOption
from toolkit.testing.action import ActionSpaceContract
from jt_actions.cvae import CVAEActionSpace
from toolkit.errors import JtError
from toolkit.priors.io import load_prior
from toolkit.priors.limits import limit_targets

STANDING = np.array([1.3, np.pi / 2, np.pi / 2])


class TestCVAE(ActionSpaceContract, FilterOption):
    @pytest.fixture(autouse=True)
    def _priors(self, action_priors):
        self.priors = action_priors

    def make(self):
        return CVAEActionSpace({"name": "cvae", "prior": str(self.priors["cvae"])})

    def obs(self, step):
        return {"condition": STANDING + [0.0, 0.0, 0.1 * step]}

    def test_filter_math(self):
        space = self.make()
        assert space.params.beta == 0.2
        rng = np.random.default_rng(0)
        acts = rng.uniform(-1, 1, (4, space.dim))
        y = np.zeros(space.dim)  # y_{-1} = 0 after reset
        space.reset()
        for a in acts:
            y = 0.2 * a + 0.8 * y
            space.targets(a, {"condition": STANDING})
            np.testing.assert_allclose(space.filtered, y, atol=1e-12)
        assert space.filter(np.zeros(space.dim)) == pytest.approx(0.8 * y)
        space.reset(state=np.ones(space.dim))
        np.testing.assert_array_equal(space.filtered, np.ones(space.dim))

    def test_targets_decode_the_filtered_latent_with_the_condition(self):
        space = self.make()
        prior = load_prior(self.priors["cvae"])
        k = prior.latent_dim
        space.set_condition(STANDING)
        a = np.concatenate([np.full(k, 0.5), np.zeros(28)])
        q = space.targets(a)
        expected = prior.decode_targets(prior.latent_from_action(0.2 * a[:k]), STANDING)
        np.testing.assert_allclose(q, limit_targets(space.skeleton, expected), atol=1e-12)
        lying = space.targets(a, {"condition": [0.2, np.pi / 2, 0.1]})
        assert not np.allclose(lying, q)

    def test_naturalness_on_filtered_offsets(self):
        space = self.make()
        k = space.latent_dim
        space.set_condition(STANDING)
        a = np.concatenate([np.zeros(k), np.ones(28)])
        space.targets(a)  # Δq = 0.2 per DoF: ||Δq||_1 = 5.6, c = 10
        assert space.penalty() == pytest.approx(1 - 0.56**2)
        space.targets(a)  # Δq = 0.36: ||Δq||_1 = 10.08 > c
        assert space.penalty() == 0.0

    def test_condition_is_required(self):
        space = self.make()
        with pytest.raises(JtError):
            space.targets(np.zeros(space.dim))
        with pytest.raises(ValueError):
            space.set_condition([1.0, 2.0])
