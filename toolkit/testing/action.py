"""The contract every jt action space meets; each action space's test module subclasses it.

A subclass sets ``make()`` (a fresh action space) and may override ``obs(step)`` (what the task
would pass as ``obs``) and ``prepare(space)`` (set-up after construction, e.g. a condition).
Targets are checked against the joint limits of jt's humanoid (``toolkit.motion.HUMANOID``)::

    from toolkit.testing.action import ActionSpaceContract

    class TestMyActions(ActionSpaceContract):
        def make(self):
            return MyActionSpace({"name": "mine"}, "humanoid")
"""

from __future__ import annotations

import numpy as np
import pytest

from toolkit.interfaces.action import ActionSpace
from toolkit.motion import HUMANOID
from toolkit.priors.limits import within_limits


class ActionSpaceContract:
    """Shapes, bounds, finite targets within the joint limits, reset, penalty in [0, 1]."""

    n_steps = 6

    def make(self) -> ActionSpace:  # pragma: no cover - every subclass defines it
        raise NotImplementedError

    def obs(self, step: int):
        return None

    def prepare(self, space: ActionSpace) -> None:
        pass

    def fresh(self) -> ActionSpace:
        space = self.make()
        self.prepare(space)
        return space

    def actions(self, space: ActionSpace, seed: int = 0) -> np.ndarray:
        """Random actions within bounds, plus both corners of the box."""
        low, high = space.bounds()
        rng = np.random.default_rng(seed)
        return np.vstack([low, high, low + (high - low) * rng.random((self.n_steps, space.dim))])

    def test_is_an_action_space_with_a_config(self):
        space = self.fresh()
        assert isinstance(space, ActionSpace)
        assert type(space).summary() and isinstance(space.params, type(space).Config)
        import dataclasses

        for f in dataclasses.fields(type(space).Config):  # every YAML key has a default
            assert f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING

    def test_dim_and_bounds(self):
        space = self.fresh()
        low, high = space.bounds()
        assert isinstance(space.dim, int) and space.dim > 0
        assert low.shape == high.shape == (space.dim,)
        assert np.all(np.isfinite(low)) and np.all(np.isfinite(high)) and np.all(low < high)

    def test_targets_finite_and_within_joint_limits(self):
        space = self.fresh()
        space.reset()
        for i, a in enumerate(self.actions(space)):
            q = space.targets(a, self.obs(i))
            assert q.shape == (HUMANOID.n_dof,)
            assert within_limits(HUMANOID, q), f"step {i}: targets outside the joint limits"

    def test_wrong_action_size_is_rejected(self):
        space = self.fresh()
        space.reset()
        with pytest.raises(ValueError):
            space.targets(np.zeros(space.dim + 1), self.obs(0))

    def test_penalty_in_unit_interval(self):
        space = self.fresh()
        space.reset()
        for i, a in enumerate(self.actions(space, seed=1)):
            space.targets(a, self.obs(i))
            assert 0.0 <= space.penalty() <= 1.0

    def test_reset_clears_state(self):
        acts = self.actions(self.fresh(), seed=2)
        first = self.fresh()
        first.reset()
        ref = [(first.targets(a, self.obs(i)), first.penalty()) for i, a in enumerate(acts)]
        space = self.fresh()
        space.reset()
        for i, a in enumerate(acts[::-1]):  # some other episode first
            space.targets(a, self.obs(i))
        space.reset()
        for i, a in enumerate(acts):
            q, pen = space.targets(a, self.obs(i)), space.penalty()
            np.testing.assert_allclose(q, ref[i][0], atol=1e-12)
            assert pen == pytest.approx(ref[i][1])
