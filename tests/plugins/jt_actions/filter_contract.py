"""The action filter (``003`` §3.4) is an option of every built-in action space (``action.beta``;
1 = no filter): a mixin each built-in space's test class adds to ``ActionSpaceContract`` (the filter
is jt's built-ins' option, not part of the interface a third-party space must meet)."""

from __future__ import annotations

import numpy as np
import pytest

from toolkit.interfaces.action import ActionSpace


class FilterOption:
    """Mixed into a built-in action space's ``ActionSpaceContract`` subclass."""

    def test_the_action_filter_is_an_option(self):
        """``action.beta`` (003 §3.4's filter, an option of every built-in space): with β = 0.5 the
        targets of actions ``a_t`` are an unfiltered copy's targets of ``y_t = β a_t + (1 - β) y_{t-1}``;
        a β outside (0, 1] is refused."""
        import dataclasses

        from toolkit.errors import JtError

        base = self.fresh()
        cls, params = type(base), dataclasses.asdict(base.params)

        def make(beta: float) -> ActionSpace:
            space = self.fresh()  # as the subclass makes it (anchored, prepared), β changed
            space.params = dataclasses.replace(space.params, beta=beta)
            space.reset()
            return space

        filtered, plain = make(0.5), make(1.0)
        assert plain.filtered is None  # no filter: the task feeds back the action itself
        y = np.zeros(filtered.dim)
        low, high = filtered.bounds()
        for i, a in enumerate(self.actions(filtered, seed=3)):
            y = 0.5 * a + 0.5 * y
            q = filtered.targets(a, self.obs(i))
            np.testing.assert_allclose(filtered.filtered, y, atol=1e-12)
            np.testing.assert_allclose(q, plain.targets(np.clip(y, low, high), self.obs(i)), atol=1e-9)
        filtered.reset()
        np.testing.assert_array_equal(filtered.filtered, np.zeros(filtered.dim))
        for bad in (0.0, 1.5, -0.2):
            with pytest.raises(JtError, match="beta"):
                cls({**params, "beta": bad}, base.character)
