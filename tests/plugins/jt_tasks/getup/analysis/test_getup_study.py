"""``jt study getup policy`` (jt_tasks.getup.analysis.study, issue 29): where a get-up policy stops, the
clip without feedback, standing balance, and its one-line refusals."""

from __future__ import annotations

import pytest

from tests.plugins.jt_tasks.getup.getup_helpers import Still, make_task


def test_the_clip_tracked_without_feedback_does_not_get_up():
    """What a policy must add (issue 29): PD targets set to the facedown clip's poses, no policy,
    lift the neck off the ground (> 0.3 m) but never to a standing height (0.8 x 1.35 m), and the
    character ends lying again."""
    from jt_tasks.getup.analysis.study import open_loop_clip

    from tests.plugins.jt_tasks.getup.getup_helpers import sim_groups

    o = open_loop_clip("getup_facedown", sim_groups(), t_stand=1.0)
    assert 0.3 < o["h_max"] < 0.8 * 1.35 and o["h_end"] < 0.3 and o["duration"] == pytest.approx(3.03, abs=0.01)


def test_standing_balance_gives_each_curve_its_standing_start_and_restores_t_stand():
    """``--stand``: a policy that holds the rest pose (raw zero action, no feedback) falls from
    every standing start well before 4 s (a PD-held pose falls in ~2 s, docs/getup.md), and the
    measurement leaves the env's 3 s standing phase as it found it."""
    from jt_tasks.getup.analysis.study import standing_balance

    e = make_task("task.curves=[facedown,faceup]", "task.p_standing=1", "task.p_fallen=0").make_env(None, seed=0)
    try:
        rows = standing_balance(e, Still(e.action_space.shape[0]), 4.0)
        assert e.spec_.t_stand == 3.0
    finally:
        e.close()
    assert [r["curve"] for r in rows] == ["facedown", "faceup"] and all(r["of"] == 120 for r in rows)
    assert all(10 < r["steps"] < 120 and r["reason"] != "time limit" for r in rows)


@pytest.mark.parametrize("argv,match", [
    (["RUN", "--stand", "0"], "--stand=0.0: the seconds of standing must be a finite number > 0"),
    (["RUN", "--stand", "nan"], "--stand=nan"),
    (["/no/such/ppo.h5", "--stand", "10"], "no such file"),
    (["RUN", "--at", "0.5", "1.0"], "--at=1.0: a clip start is a fraction of the clip in [0, 1)"),
])
def test_study_refuses_a_bad_value_in_one_line_with_exit_2(argv, match, capsys):
    from jt_tasks.getup.analysis.study import main

    with pytest.raises(SystemExit) as e:
        main(argv)
    err = capsys.readouterr().err
    assert e.value.code == 2 and match in err and len(err.strip().splitlines()) == 1


def test_another_tasks_run_and_an_unwritable_out_are_one_line_before_any_episode(tmp_path, capsys):
    """A task=spacetime run's ppo.h5 (its config.yaml beside it) is refused by its task; an --out
    under a file is refused before the policy is loaded (the ppo.h5 here is not even one)."""
    from omegaconf import OmegaConf

    from jt_tasks.getup.analysis.study import main
    from toolkit.config import compose

    (tmp_path / "ppo.h5").write_bytes(b"not read")
    (tmp_path / "file").write_text("")
    for task, argv, match in (
            ("spacetime", [str(tmp_path / "ppo.h5")],
             "a task=spacetime run; jt study getup policy reads task=getup runs"),
            ("getup", [str(tmp_path / "ppo.h5"), "--out", str(tmp_path / "file" / "plots")], "--out=")):
        OmegaConf.save(compose([f"task={task}", "experiment=smoke"]), tmp_path / "config.yaml")
        with pytest.raises(SystemExit) as e:
            main(argv)
        err = capsys.readouterr().err
        assert e.value.code == 2 and err.startswith("jt: ") and match in err and len(err.strip().splitlines()) == 1


def test_policy_starts_at_chosen_fractions_say_what_a_success_needs():
    """``--at``: episodes from the clip at the given fractions, each with the control steps a
    success lasts from there; the rest-pose policy lasts fewer than that from every one."""
    from jt_tasks.getup.analysis.study import policy_starts

    e = make_task("task.curves=[facedown,faceup]").make_env(None, seed=0)
    try:
        rows = policy_starts(e, Still(e.action_space.shape[0]), curves=("facedown",), fractions=(0.8,))
    finally:
        e.close()
    assert [r["start"] for r in rows] == ["clip at 80%", "standing"]
    assert rows[0]["needs"] == round((0.2 * e.curves[0].duration + 3.0) * 30) and rows[0]["steps"] < rows[0]["needs"]


def test_the_history_plot_reads_its_columns_by_name(tmp_path):
    """``--out``: getup_history.png from the rows ``(samples, *HISTORY)`` the training keeps; none
    without them."""
    import h5py
    import numpy as np

    from jt_tasks.getup.analysis.study import plot_history
    from jt_tasks.getup.task import HISTORY

    with h5py.File(tmp_path / "ppo.h5", "w") as f:
        rows = np.random.default_rng(0).random((5, len(HISTORY)))
        f["extra/getup_history"] = np.column_stack([np.arange(1, 6) * 64.0, rows])
        f["extra/eval_history"] = np.array([[128.0, 0.0, 0.5], [256.0, 0.5, 1.0]])
    path = plot_history(tmp_path / "ppo.h5", tmp_path)
    assert path == tmp_path / "getup_history.png" and path.read_bytes()[:4] == b"\x89PNG"
    with h5py.File(tmp_path / "empty.h5", "w") as f:
        f["history/mean_return"] = np.zeros(2)
    assert plot_history(tmp_path / "empty.h5", tmp_path) is None
