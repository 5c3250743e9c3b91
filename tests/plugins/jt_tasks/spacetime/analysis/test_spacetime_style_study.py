"""``style_study``: replaying a run's final policy gives the run's own style measures, windowed."""

from __future__ import annotations

import math

import pytest


def test_replay_reproduces_the_logged_style_measures_and_windows_are_prefixes(tmp_path):
    from jt_tasks.spacetime.analysis import style_study
    from toolkit import plugins
    from toolkit.config import compose
    from toolkit.interfaces.task import EvalContext

    cfg = compose(["task=spacetime", "experiment=smoke"])
    ev = plugins.load("task", "spacetime")(cfg).evaluate({}, EvalContext(index=0, seed=3, workdir=tmp_path))
    env, ro = style_study.replay(cfg, str(tmp_path / "ppo.h5"))
    try:
        first = ev.metrics.get("survival_first_s", ev.metrics["survival_s"])  # the final rollout (eval_phase)
        assert float(ro.info["survival_s"]) == pytest.approx(first, abs=1e-12)
        short, whole = style_study.windows(env, ro, [0.2, None])
    finally:
        env.close()
    m = ev.metrics
    for ours, logged in (("volume", "style_volume"), ("ref_volume", "ref_volume"),
                         ("energy", "style_energy"), ("ref_energy", "ref_energy")):
        assert whole[ours] == pytest.approx(m[logged], rel=1e-9)  # the same rollout, the same estimator
    assert math.isnan(whole["seconds"]) and whole["steps"] == m["survival_steps"] + 1
    assert short["steps"] == 7 and short["volume"] != whole["volume"]  # 0.2 s at 30 Hz: the first 7 states


def test_bad_input_is_one_line_and_exit_2(tmp_path, capsys):
    """No store, an unknown run id: one ``jt:`` line on stderr, status 2, nothing printed before it."""
    from jt_tasks.spacetime.analysis import style_study
    from toolkit.store.tracking import Store

    Store(tmp_path / "store")  # a real, empty store
    for argv, said in ((["abc", "--store", str(tmp_path / "none")], "no jt store at"),
                       (["abc", "--store", str(tmp_path / "store")], "no run 'abc'"),
                       (["abc", "--seconds", "0"], "--seconds=0.0: a window is a finite number of seconds > 0")):
        with pytest.raises(SystemExit) as e:
            style_study.main(argv)
        out, err = capsys.readouterr()
        assert e.value.code == 2 and out == ""
        assert err.startswith("jt: ") and said in err and err.count("\n") == 1
