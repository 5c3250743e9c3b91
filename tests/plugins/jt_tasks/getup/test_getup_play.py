"""``jt play`` on a get-up policy: the starts it offers and the line it prints (got up, stood)."""

import pytest

from toolkit.errors import JtError


def test_play_starts_and_summary():
    from getup_helpers import Still, make_task
    from toolkit.policy.episodes import opened_env, rollout

    task = make_task("task.curves=[facedown,faceup]")
    with opened_env(task.make_env, {}, seed=0) as env:
        assert task.play_options(env) == {"kind": "clip", "curve": "facedown"}
        assert task.play_options(env, "faceup") == {"kind": "clip", "curve": "faceup"}
        with pytest.raises(JtError, match="one of facedown, faceup"):
            task.play_options(env, "sideways")
        with pytest.raises(JtError, match="task.n_fallen=0"):
            task.play_options(env, "drop")
        ro = rollout(env, Still(env.action_space.shape[0]), task.record, options=task.play_options(env, "faceup"))
        measure, line = task.play_summary(env, ro)
    assert measure["got_up"] is False and measure["stood"] is False and measure["time_to_rise_s"] is None
    assert 0.05 < measure["peak_h_m"] < 0.8  # the rest pose lies on the floor
    assert line.startswith("did not get up: neck at most ") and "control steps" in line
