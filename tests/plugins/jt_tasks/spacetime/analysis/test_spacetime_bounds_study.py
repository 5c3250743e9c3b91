"""What early termination saves: the tally and a real bounds-off FFC episode (002 §3.2)."""

from __future__ import annotations

import math

import pytest

from jt_tasks.spacetime.analysis.bounds_study import study, tally


def test_tally_counts_the_steps_that_never_return_inside():
    assert tally([True, True, False, True, False, False]) == {"steps": 6, "first": 2, "after": 4, "lost": 2}
    assert tally([True, False, False]) == {"steps": 3, "first": 1, "after": 2, "lost": 2}
    assert tally([True, False, True]) == {"steps": 3, "first": 1, "after": 2, "lost": 0}
    assert tally([True, True]) == {"steps": 2, "first": None, "after": 0, "lost": 0}


def test_the_ffc_alone_leaves_the_run_bounds_and_the_study_counts_it():
    (row,) = study(["run"], n_starts=2, seconds=1.0)
    assert row["episodes"] == 2 and row["violated"] >= 1  # the untrained FFC leaves the bounds in < 1 s
    assert 0 < row["first_s"] < 1.0 and 0 <= row["lost"] <= row["after"] <= row["steps"]
    assert math.isfinite(row["share_lost"]) and 0.0 <= row["share_lost"] <= 1.0


@pytest.mark.parametrize("argv, match", [
    (["--clips", "run", "nosuch"], "--clips: task.clip='nosuch': no such clip"),
    (["--starts", "0"], "--starts=0: at least 1"),
    (["--seconds", "-1"], "--seconds=-1.0: a finite number of seconds > 0"),
])
def test_bad_input_is_one_line_before_any_episode(capsys, argv, match):
    from jt_tasks.spacetime.analysis.bounds_study import main

    with pytest.raises(SystemExit) as e:
        main(argv)
    out, err = capsys.readouterr()
    assert e.value.code == 2 and out == "" and match in err and len(err.strip().splitlines()) == 1
