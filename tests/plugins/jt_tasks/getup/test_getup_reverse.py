"""The reverse curriculum over starts inside the clip (task.rsi_from / rsi_step, jt_tasks.getup.reverse);
its bad values are in test_getup_stage1.py."""

from __future__ import annotations

import types

import numpy as np
import pytest

from tests.plugins.jt_tasks.getup.test_getup_stage1 import make_task


def stats(*episodes: dict):
    return types.SimpleNamespace(episodes=list(episodes))


def test_starts_inside_the_clip_begin_at_the_window_front_and_follow_it():
    e = make_task("task.rsi=1.0", "task.rsi_from=0.6", "task.p_standing=0", "task.p_fallen=0").make_env(None, seed=0)
    try:
        fracs = [e.reset(seed=s)[1]["start_time"] / e.curve.duration for s in range(16)]
        assert min(fracs) >= 0.6 and max(fracs) < 1.0 and np.std(fracs) > 0.05
        e.set_wrapper_attr("rsi_from", 0.0)  # as the trainer sets it (rollout.set_env_attrs)
        wide = [e.reset(seed=s)[1]["start_time"] / e.curve.duration for s in range(16)]
        assert min(wide) < 0.5  # the trainer moved the front: the next draws use it
        info, done = {}, False
        while not done:
            _, _, te, tr, info = e.step(np.zeros(e.action_space.shape, np.float32))
            done = te or tr
        assert info["start_frac"] == pytest.approx(e.start_time / e.curve.duration)
    finally:
        e.close()


def test_the_front_moves_back_once_the_newest_band_succeeds():
    from jt_tasks.getup.reverse import MOVES_KEY, StartWindow

    extra: dict = {}
    w = StartWindow(0.75, 0.25, 0.5, 4, extra, then=lambda i, s, st: {"terrain_level": 1})
    band_fail, band_ok = {"start_frac": 0.8, "success": 0.0}, {"start_frac": 0.9, "success": 1.0}
    later, ground = {"start_frac": 0.5, "success": 1.0}, {"success": 1.0}  # outside the band: not counted
    assert w(1, 100, stats(band_ok, band_ok, later, ground)) == {"terrain_level": 1, "rsi_from": 0.75}
    assert w(2, 200, stats(band_fail)) == {"terrain_level": 1, "rsi_from": 0.75}  # 3 of the band's 4: too few
    assert w(3, 300, stats(band_fail)) == {"terrain_level": 1, "rsi_from": 0.5}  # 2 of 4 = 0.5: moves
    assert w.outcomes() == [] and extra[MOVES_KEY].tolist() == [[300.0, 0.5]]
    # the next band is [0.5, 0.75): old-band successes no longer count
    assert w(4, 400, stats(band_ok, band_ok, band_ok, band_ok))["rsi_from"] == 0.5
    # a resumed run: a new hook on the checkpoint's extra goes on where it stopped
    again = StartWindow(0.75, 0.25, 0.5, 4, extra)
    assert again.front == 0.5 and again(5, 500, stats(*[later] * 3, {"start_frac": 0.55, "success": 0.0})) == \
        {"rsi_from": 0.25}
    again(6, 600, stats(*[{"start_frac": 0.3, "success": 1.0}] * 4))
    assert again.front == 0.0 and again(7, 700, stats(*[{"start_frac": 0.1, "success": 1.0}] * 9))["rsi_from"] == 0.0


def test_a_fixed_window_never_moves():
    from jt_tasks.getup.reverse import StartWindow

    w = StartWindow(0.5, 0.0, 0.5, 2, {})
    assert w(1, 1, stats(*[{"start_frac": 0.9, "success": 1.0}] * 5)) == {"rsi_from": 0.5}


def test_a_training_run_carries_the_front_into_its_metrics_and_history(tmp_path):
    """The hook is wired into task=getup's training: an untrained policy never stands at the end, so
    the front stays where it began, and the run reports it (a run without the window does not)."""
    from toolkit import plugins
    from toolkit.config import compose, validate
    from toolkit.interfaces.task import EvalContext

    base = ["task=getup", "experiment=smoke", "task.p_standing=0", "task.p_fallen=0", "task.rsi=1.0",
            "task.eval_regions=[]", "task.filmstrip_frames=0"]
    runs = {}
    for name, extra in (("window", ["task.rsi_from=0.6", "task.rsi_step=0.2", "task.rsi_episodes=1"]), ("plain", [])):
        task = plugins.load("task", "getup")(validate(compose(base + extra)))
        (tmp_path / name).mkdir()
        runs[name] = task.evaluate({}, EvalContext(index=0, seed=0, workdir=tmp_path / name))
    assert runs["window"].metrics["rsi_from_final"] == pytest.approx(0.6)
    assert runs["window"].history["rsi_from"] == [(0, 0.6)]
    assert "rsi_from_final" not in runs["plain"].metrics and "rsi_from" not in runs["plain"].history
