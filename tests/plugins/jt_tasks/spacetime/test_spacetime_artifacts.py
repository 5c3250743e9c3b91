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
    assert d["width"].shape == d["ref_phase"].shape and np.allclose(d["width"], 0.2)  # 002 §5.1 CoM width
    assert np.ptp(d["ref_com_y"]) > 0.02  # the run's CoM bobs
    out = plot_com_bounds(d, tmp_path / "com_bounds.png")
    assert out.stat().st_size > 5000


def test_reference_frames_pose_the_clip_in_a_second_world_with_the_envs_camera():
    from jt_tasks.spacetime.artifacts import reference_frames

    env = make_env(seed=0)
    try:
        env.reset(seed=0, options={"phase": 0.3})
        q_before = env.sim.state()[0]
        first = env.render_frame(64, 48)
        ref = reference_frames(env, np.array([0.0, 0.2, 0.4]), 64, 48)
        assert np.array_equal(env.sim.state()[0], q_before)  # the env's own world is untouched
    finally:
        env.close()
    assert [f.shape for f in ref] == [(48, 64, 3)] * 3
    assert np.abs(ref[0].astype(int) - first.astype(int)).mean() < 1.0  # the start is the reference state
    assert np.abs(ref[2].astype(int) - ref[0].astype(int)).mean() > 1.0  # the reference moves


def test_smoke_evaluation_writes_the_policy_beside_the_reference(tmp_path):
    import imageio.v3 as iio
    from toolkit import plugins
    from toolkit.config import compose
    from toolkit.interfaces.task import EvalContext

    cfg = compose(["task=spacetime", "experiment=smoke"])
    ev = plugins.load("task", "spacetime")(cfg).evaluate({}, EvalContext(index=0, seed=3, workdir=tmp_path))
    assert "motion_vs_reference.gif" in ev.artifacts
    both = iio.imread(tmp_path / "motion_vs_reference.gif", index=None)[..., :3].astype(int)
    alone = iio.imread(tmp_path / "motion.gif", index=None)[..., :3].astype(int)
    n, h, w = alone.shape[:3]  # smoke frames (64 x 48) are not enlarged
    assert both.shape[:3] == (n, h, 2 * w + 2) and n == ev.metrics["survival_steps"] + 1  # a frame per control step
    policy, gap, ref = both[:, :, :w], both[:, :, w:w + 2], both[:, :, w + 2:]
    assert (gap == 255).all()
    assert np.abs(policy - alone).mean() < 2.0  # left: the rollout (GIF palettes differ a little)
    assert np.abs(ref[0] - policy[0]).mean() < 1.0  # both start in the reference state at eval_phase
    steps = [np.abs(ref[i + 1] - ref[i]).mean() for i in range(n - 1)]
    assert min(steps) > 0.1  # the reference half changes every frame
    # the style measures of the rollout and of the reference at the same clip times (002 §3.3)
    m = ev.metrics
    assert {"style_energy", "ref_energy", "style_volume", "ref_volume"} <= set(m)
    assert 0.05 < m["ref_volume"] < 0.25 and 5.0 < m["ref_energy"] < 150.0  # the run clip (research notes: 0.155 m³, 64 J medians)
    assert m["style_volume"] == pytest.approx(m["ref_volume"], rel=0.5)  # 1 s from the reference state


def test_style_measures_of_a_translating_cube_are_half_m_v_squared_and_one():
    """A rigid unit cube of joint origins moving up at 2 m/s (link CoMs with it): eq 4's energy is
    ½ M v² (a vertical motion keeps it all), eq 5's volume 1; sideways the energy is 0."""
    from jt_tasks.spacetime.artifacts import style_measures

    cube = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    links = np.array([[0.0, 0.5, 0.0], [0.3, 0.2, 0.1], [0.0, 0.9, 0.4]])
    masses = np.array([1.0, 2.0, 3.0])
    up = [(links + [0.0, 2.0 * k / 30.0, 0.0], cube) for k in range(5)]
    side = [(links + [2.0 * k / 30.0, 0.0, 0.0], cube) for k in range(5)]
    m = style_measures(up, masses, 30.0)
    assert m["energy"] == pytest.approx(0.5 * 6.0 * 4.0) and m["volume"] == pytest.approx(1.0)
    assert style_measures(side, masses, 30.0)["energy"] == pytest.approx(0.0, abs=1e-9)
    assert np.isnan(style_measures([], masses, 30.0)["energy"])
