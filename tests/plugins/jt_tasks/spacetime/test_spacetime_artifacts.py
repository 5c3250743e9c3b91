"""The Fig. 5 analogue (CoM height vs phase with the com_y bounds) and the IS plot (real PyBullet)."""

from __future__ import annotations

import numpy as np
import pytest

from spacetime_helpers import make_env


def test_com_height_data_puts_the_reference_start_on_the_reference_curve(tmp_path):
    from jt_tasks.spacetime.artifacts import com_height_data, plot_com_bounds

    env = make_env(seed=0)
    try:
        env.reset(seed=0, options={"phase": 0.3})
        com = [env.links_and_com()[1]]
        times = [0.0]
        for _ in range(3):
            env.step(np.zeros(env.action_space.shape, np.float32))
            com.append(env.links_and_com()[1])
            times.append(env.t)
        d = com_height_data(env, np.array(times), np.array(com))
    finally:
        env.close()
    assert d["phase"][0] == pytest.approx(0.3) and np.all(np.diff(d["phase"]) > 0)
    ref_at_start = np.interp(0.3, d["ref_phase"], d["ref_com_y"])
    assert d["com_y"][0] == pytest.approx(ref_at_start, abs=0.01)  # starts in the reference state
    assert float(d["width"]) == pytest.approx(0.2)  # 002 §5.1 CoM width
    assert np.ptp(d["ref_com_y"]) > 0.02  # the run's CoM bobs
    out = plot_com_bounds(d, tmp_path / "com_bounds.png")
    assert out.stat().st_size > 5000
