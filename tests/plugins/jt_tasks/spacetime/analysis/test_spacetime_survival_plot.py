"""``survival_plot``: Table 1's survival against samples from runs' ``ppo.h5``."""

from __future__ import annotations

import numpy as np
import pytest

from jt_tasks.spacetime.analysis import survival_plot


@pytest.fixture(scope="module")
def smoke_run(tmp_path_factory):
    """A smoke run's workdir: 2 iterations, Table 1's evaluation after each (4 starts, 1 s)."""
    from toolkit import plugins
    from toolkit.config import compose
    from toolkit.interfaces.task import EvalContext

    work = tmp_path_factory.mktemp("smoke")
    cfg = compose(["task=spacetime", "experiment=smoke"])
    plugins.load("task", "spacetime")(cfg).evaluate({}, EvalContext(index=0, seed=3, workdir=work))
    return work


def test_a_runs_rows_are_its_evaluations_and_the_plot_is_drawn(smoke_run, tmp_path, capsys):
    rows = survival_plot.read_rows(smoke_run / "ppo.h5")
    assert rows.shape == (2, 4) and list(rows[:, 0]) == [64.0, 128.0]  # one evaluation per iteration
    assert np.all((0.0 < rows[:, 3]) & (rows[:, 3] <= rows[:, 1]) & (rows[:, 1] <= 1.0 + 1e-9))
    out = tmp_path / "s.png"
    survival_plot.main([f"{smoke_run / 'ppo.h5'}=smoke", str(smoke_run), "--out", str(out)])
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[0].startswith("smoke ") and "(2 evaluations)" in lines[0] and len(lines) == 3
    assert out.stat().st_size > 5000 and out.read_bytes()[:4] == b"\x89PNG"


def test_samples_to_20s_is_the_first_evaluation_all_starts_survived():
    rows = np.array([[1e5, 3.0, 0.0, 2.0], [2e5, 20.0, 1.0, 20.0], [3e5, 12.0, 0.5, 4.0]])
    line = survival_plot.summary("walk", rows)
    assert "samples_to_20s   0.20 M" in line and "worst 4.00 s" in line
    assert "samples_to_20s        -" in survival_plot.summary("run", rows[[0, 2]])


@pytest.mark.parametrize("argv, match", [
    (["nosuchrun", "--store", "{tmp}"], "run=nosuchrun: no such run"),
    (["{tmp}/x.h5", "--out", "{tmp}/s.pdf"], "--out={tmp}/s.pdf: the plot is a .png"),
    (["{tmp}/empty.h5"], "no Table 1 evaluation in it"),
    (["{tmp}/getup/ppo.h5"], "{tmp}/getup/ppo.h5: a task=getup run; jt study spacetime survival reads task=spacetime"),
    (["{tmp}/noth5.h5"], "not a readable ppo.h5"),
    (["{tmp}/getup/ppo.h5", "--out", "{tmp}/file/s.png"], "a task=getup run"),  # the input first
    (["{tmp}/x.h5", "--out", "{tmp}/file/s.png"], "--out={tmp}/file/s.png: cannot write there"),
    (["{tmp}/x.h5", "--nosuch"], "jt study spacetime survival: unrecognized arguments: --nosuch"),
])
def test_bad_input_is_one_line(tmp_path, capsys, argv, match):
    import h5py

    for name in ("empty.h5", "x.h5"):
        with h5py.File(tmp_path / name, "w") as f:
            f.create_dataset("history/mean_length", data=np.zeros(3))  # a ppo.h5 of another task
    with h5py.File(tmp_path / "x.h5", "a") as f:
        f.create_dataset("extra/eval_history", data=np.ones((2, 4)))
    (tmp_path / "getup").mkdir()
    (tmp_path / "getup" / "config.yaml").write_text("task:\n  name: getup\n")  # a run's work folder
    (tmp_path / "getup" / "ppo.h5").write_bytes((tmp_path / "x.h5").read_bytes())
    (tmp_path / "noth5.h5").write_text("not HDF5")
    (tmp_path / "file").write_text("")
    with pytest.raises(SystemExit) as e:
        survival_plot.main([a.replace("{tmp}", str(tmp_path)) for a in argv])
    assert e.value.code == 2
    err = capsys.readouterr().err.strip()
    assert match.replace("{tmp}", str(tmp_path)) in err and len(err.splitlines()) == 1
