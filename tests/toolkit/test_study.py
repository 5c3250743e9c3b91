"""``jt study TASK TOOL ...`` (toolkit/study.py): every task's analysis tools behind one door, listed,
found by name, their mistakes one line with exit status 2, as a user meets them."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import jt_env, one_line_error, run_jt
from toolkit.errors import JtError


@pytest.fixture(scope="module")
def jump_ppo(tmp_path_factory):
    """A real ``ppo.h5`` of a smoke ``task=highjump`` evaluation (2 PPO iterations, no filmstrip)."""
    from toolkit import plugins
    from toolkit.config import compose
    from toolkit.interfaces.task import EvalContext

    work = tmp_path_factory.mktemp("jump") / "eval_0000"
    work.mkdir()
    cfg = compose(["task=highjump", "search=bds", "experiment=smoke", "task.filmstrip_frames=0"])
    plugins.load("task", "highjump")(cfg).evaluate({"alpha": -0.05, "omega_x": -3.0, "omega_z": 1.0, "v_z": -2.4},
                                                   EvalContext(index=0, seed=7, workdir=work))
    return work / "ppo.h5"


def test_jt_study_lists_every_tasks_tools_with_their_summaries():
    from toolkit import study

    every = study.studies()
    assert {"survival", "bounds", "policy-bounds", "style", "toy"} <= set(every["spacetime"])
    assert "curves" in every["highjump"] and "policy" in every["getup"]
    p = run_jt("study")
    assert p.returncode == 0, p.stderr
    lines = p.stdout.splitlines()
    assert lines[0].startswith("jt study TASK TOOL [ARGS...]")
    listed = {tuple(ln.split()[2:4]) for ln in lines[1:]}
    assert listed == {(t, tool) for t, tools in every.items() for tool in tools}
    for ln in lines[1:]:  # each with its module's one-line summary
        assert len(ln.split(None, 4)) == 5, ln
    survival = next(ln for ln in lines if "jt study spacetime survival" in ln)
    assert "Survival against samples" in survival
    assert any("jt study highjump curves" in ln and "Learning curves" in ln for ln in lines)
    one = run_jt("study", "spacetime")  # one task's tools only
    assert one.returncode == 0 and all(ln.startswith("jt study spacetime ") for ln in one.stdout.splitlines())
    assert len(one.stdout.splitlines()) == len(every["spacetime"])


def test_an_unknown_task_or_tool_is_one_line_naming_the_choices():
    err = one_line_error(run_jt("study", "nosuch"))
    assert "no study tools for task 'nosuch'" in err and "spacetime" in err and "highjump" in err
    err = one_line_error(run_jt("study", "spacetime", "nosuch"))
    assert err == ("jt: unknown tool 'nosuch' of task=spacetime; "
                   "choose one of: bounds, policy-bounds, style, survival, toy")


def test_a_tools_bad_argument_is_one_line_and_help_is_its_usage(tmp_path):
    err = one_line_error(run_jt("study", "highjump", "curves", "--nosuch"))
    assert err.startswith("jt: jt study highjump curves: ") and "(see jt study highjump curves --help)" in err
    err = one_line_error(run_jt("study", "highjump", "curves", str(tmp_path / "x.h5"), "--nosuch"))
    assert "unrecognized arguments: --nosuch" in err
    err = one_line_error(run_jt("study", "highjump", "curves", str(tmp_path / "missing.h5")))
    assert err == f"jt: file {tmp_path / 'missing.h5'}: no such file"
    h = run_jt("study", "highjump", "curves", "--help")
    assert h.returncode == 0 and h.stdout.startswith("usage: jt study highjump curves ") and h.stderr == ""
    assert "--labels" in h.stdout and "--out" in h.stdout


def test_every_tools_help_is_its_usage_under_jt_study(capsys):
    """Each registered tool builds its parser with ``study.parser``: ``--help`` exits 0 with a usage
    naming ``jt study ... TOOL``, and a bad option is a ``JtError`` line (exit 2), not argparse's block."""
    from toolkit import study

    for task, tools in study.studies().items():
        for tool in tools:
            main = study.find(task, tool)
            with pytest.raises(SystemExit) as e:
                main(["--help"])
            out = capsys.readouterr().out
            assert e.value.code == 0 and out.startswith("usage: jt study ") and f" {tool} " in out.splitlines()[0], \
                (task, tool, out[:200])
            with pytest.raises(SystemExit) as e:
                main(["--no-such-option"])
            err = capsys.readouterr().err
            assert e.value.code == 2 and err.startswith("jt: jt study ") and len(err.strip().splitlines()) == 1, \
                (task, tool, err)


def test_find_and_listing_refuse_in_one_line():
    from toolkit import study

    with pytest.raises(JtError, match=r"no study tools for task 'nosuch'; tasks with tools: .*spacetime"):
        study.find("nosuch", "x")
    with pytest.raises(JtError, match=r"unknown tool 'x' of task=getup; choose one of: policy"):
        study.find("getup", "x")
    with pytest.raises(JtError, match="no study tools for task 'nosuch'"):
        study.listing("nosuch")


def test_jump_curves_of_a_smoke_run_write_the_png(jump_ppo, tmp_path):
    out = tmp_path / "plots" / "curves.png"
    p = run_jt("study", "highjump", "curves", str(jump_ppo), "--labels", "smoke", "--out", str(out))
    assert p.returncode == 0, p.stderr
    assert out.read_bytes()[:4] == b"\x89PNG" and out.stat().st_size > 5000
    rows = [ln for ln in p.stdout.splitlines() if ln.startswith("| smoke |")]
    assert rows and p.stdout.strip().splitlines()[-1] == str(out)
    # the same tool as a module, as before
    m = subprocess.run([sys.executable, "-m", "jt_tasks.jumping.analysis.curves", str(jump_ppo), "--out",
                        str(tmp_path / "m.png")], capture_output=True, text=True, env=jt_env(), cwd=tmp_path)
    assert m.returncode == 0, m.stderr
    assert (tmp_path / "m.png").read_bytes()[:4] == b"\x89PNG"


def test_jump_curves_refuse_another_tasks_file_and_an_unwritable_out_in_one_line(jump_ppo, tmp_path):
    import h5py
    import numpy as np

    other = tmp_path / "spacetime" / "ppo.h5"
    other.parent.mkdir()
    with h5py.File(other, "w") as f:  # a ppo.h5 of another task: no curriculum curve
        f.create_dataset("history/mean_return", data=np.zeros(2))
    err = one_line_error(run_jt("study", "highjump", "curves", str(other)))
    assert "no jump curriculum curve in it (extra/z_history)" in err
    (other.parent / "config.yaml").write_text("task:\n  name: spacetime\n")  # a run's work folder says so
    err = one_line_error(run_jt("study", "highjump", "curves", str(other)))
    assert err == (f"jt: {other}: a task=spacetime run; "
                   "jt study highjump curves reads task=highjump/obstacle/longjump runs")
    (tmp_path / "file").write_text("")
    err = one_line_error(run_jt("study", "highjump", "curves", str(jump_ppo), "--out", str(tmp_path / "file" / "c.png")))
    assert err.startswith(f"jt: --out={tmp_path / 'file' / 'c.png'}: cannot write there")
    err = one_line_error(run_jt("study", "highjump", "curves", str(jump_ppo), "--out", str(tmp_path / "c.pdf")))
    assert "--out=" in err and "a .png file" in err
    err = one_line_error(run_jt("study", "highjump", "curves", str(jump_ppo), str(jump_ppo), "--labels", "one"))
    assert "--labels: 1 labels for 2 files" in err


def test_output_checks_create_nothing_they_do_not_need(tmp_path):
    from toolkit import study

    f = study.writable_file(tmp_path / "a" / "b.png", "--out", suffix=".png")
    assert f.parent.is_dir() and not f.exists()  # the folder as writing makes it, no file left
    d = study.writable_folder(tmp_path / "c" / "d", "--out")
    assert d.is_dir() and not any(d.iterdir())
    with pytest.raises(JtError, match="is a folder"):
        study.existing_file(tmp_path, "file")
    with pytest.raises(JtError, match=r"--out=.*: cannot write there"):
        study.writable_file(tmp_path / "c", "--out")  # a folder, not a file


def test_task_of_reads_the_config_beside_the_file(tmp_path):
    from toolkit import study

    (tmp_path / "eval_0000").mkdir()
    (tmp_path / "config.yaml").write_text("task:\n  name: getup\n")
    assert study.task_of(tmp_path / "eval_0000" / "ppo.h5") == "getup"  # the work folder's, one up
    assert study.task_of(tmp_path.parent / "elsewhere.h5") is None
    with pytest.raises(JtError, match="a task=getup run; jt study spacetime survival reads task=spacetime runs"):
        study.require_task(tmp_path / "eval_0000" / "ppo.h5", "RUN", "spacetime", "jt study spacetime survival")
    study.require_task(tmp_path / "eval_0000" / "ppo.h5", "RUN", "getup", "jt study getup policy")
