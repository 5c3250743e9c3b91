"""The shipped contract suites (``toolkit.testing``) leave nothing in the temporary folder: the
searcher suite made a ``jt_contract_*`` folder per run of a searcher and never removed it (7,000
of them in /tmp on the development machine)."""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

from jt_searchers.random_search import RandomSearcher
from toolkit.interfaces import Evaluation, Param, SearchProblem, Space, Task
from toolkit.testing.searcher import run_batches


class WritingTask(Task):
    """Writes a file in its evaluation's working folder, as real tasks do."""

    def problem(self):
        return SearchProblem(space=Space((Param("x", -1.0, 1.0, 0.0),)))

    def evaluate(self, point, ctx):
        (Path(ctx.workdir) / f"eval{ctx.index}.txt").write_text(str(point["x"]))
        return Evaluation(metrics={"x": point["x"]})


def test_run_batches_removes_its_folder_and_what_the_task_wrote(tmp_path, monkeypatch):
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))  # where mkdtemp / TemporaryDirectory go
    task = WritingTask(None)
    batches = run_batches(RandomSearcher(task.problem(), {"budget": 4}, 0), task, 2, seed=0)
    assert sum(len(X) for X, _ in batches) == 4
    assert list(tmp_path.iterdir()) == []


def test_run_batches_uses_a_given_folder_and_leaves_it(tmp_path):
    task = WritingTask(None)
    run_batches(RandomSearcher(task.problem(), {"budget": 3}, 0), task, 1, seed=0, workdir=tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["eval0.txt", "eval1.txt", "eval2.txt"]


SUITE = '''
from tests.toolkit.testing.test_suites_leave_no_temp import WritingTask
from jt_searchers.random_search import RandomSearcher
from toolkit.testing.searcher import SearcherContract

class TestRandomOnAWritingTask(SearcherContract):
    searcher_cls, cfg, batch = RandomSearcher, {"budget": 6, "batch": 2}, 2
    def make_task(self):
        return WritingTask(None)
'''


def test_the_searcher_suite_leaves_nothing_behind(tmp_path):
    """The whole searcher suite, run by pytest with its own temporary folder (``TMPDIR``) and
    pytest's ``tmp_path`` folders elsewhere: nothing is left in ``TMPDIR``, and the task wrote
    nothing in the current folder."""
    root = Path(__file__).resolve().parents[3]
    (tmp_path / "tmp").mkdir()
    (tmp_path / "cwd").mkdir()
    (tmp_path / "cwd" / "test_suite.py").write_text(SUITE)
    out = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--rootdir",
                          str(tmp_path / "cwd"), f"--basetemp={tmp_path / 'pytest'}", "test_suite.py"],
                         cwd=tmp_path / "cwd", capture_output=True, text=True, timeout=300,
                         env={"PATH": "/usr/bin:/bin", "TMPDIR": str(tmp_path / "tmp"), "PYTHONPATH": str(root),
                              "HOME": str(tmp_path)})
    assert out.returncode == 0 and " passed" in out.stdout, out.stdout[-3000:] + out.stderr[-2000:]
    assert list((tmp_path / "tmp").iterdir()) == []
    assert not list((tmp_path / "cwd").glob("eval*"))  # not written in the current folder either
