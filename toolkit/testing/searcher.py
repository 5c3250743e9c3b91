"""The contract every searcher passes (``jt.searchers``): bounds, batches, budget, determinism,
resume, a summary that goes to HDF5.

Shipped with jt so a third-party searcher is tested by the same suite as the built-ins::

    from toolkit.testing.searcher import SearcherContract

    class TestMySearcher(SearcherContract):
        searcher_cls = MySearcher
        cfg = {"name": "mine", "budget": 12}
        def make_task(self):
            return MyTask(None)

A subclass sets ``searcher_cls``, ``cfg`` (a dict for the search group; it must have ``budget``),
``batch`` (points per ``ask``, 1 by default) and ``make_task()``; the test methods here then run
against the real task. A searcher may stop before its budget when it has converged: the suite
accepts that only from a searcher with a ``_converged()`` method that says so.

Golden points (first points for seed 0) are optional: set ``golden_name`` and they are read from
``golden/<golden_name>.json`` next to the subclass's test module (``golden_dir`` overrides the
folder); regenerate them with ``JT_REGEN_GOLDEN=1 python -m pytest <tests> -k golden`` and commit
the JSON only when the change of points is intended.
"""

from __future__ import annotations

import inspect
import json
import os
import tempfile
from pathlib import Path
from typing import Any, ClassVar, Optional

import numpy as np
import pytest

from toolkit.interfaces.task import EvalContext


def eval_seed(run_seed: int, index: int) -> int:
    """Seed of evaluation ``index`` of a run, derived from the run seed."""
    return int(np.random.SeedSequence([run_seed, index]).generate_state(1)[0])


def run_batches(searcher: Any, task: Any, batch: int, seed: int, max_batches: int = 10_000,
                workdir: Optional[Path] = None) -> list[tuple[np.ndarray, list]]:
    """Drive ``searcher`` to the end; the recorded ``(X, evaluations)`` of every batch.

    Args:
        searcher: the searcher under test.
        task: the task whose ``evaluate`` answers each point.
        batch: points per ``ask``.
        seed: the run seed evaluation seeds derive from (``eval_seed``).
        max_batches: a bound on the number of asks.
        workdir: the evaluations' working folder (pytest's ``tmp_path`` in the suite's tests).
            None: a temporary folder, removed, with whatever the task wrote there, before this
            returns (the evaluations returned keep their metrics, not their files).
    """
    if workdir is None:
        with tempfile.TemporaryDirectory(prefix="jt_contract_") as tmp:
            return run_batches(searcher, task, batch, seed, max_batches, Path(tmp))
    problem = task.problem()
    out, n = [], 0
    for _ in range(max_batches):
        if searcher.finished():
            break
        X = searcher.ask(batch)
        if len(X) == 0:
            break
        evs = []
        for x in X:
            evs.append(task.evaluate(problem.space.to_dict(x), EvalContext(n, eval_seed(seed, n), Path(workdir))))
            n += 1
        searcher.tell(X, evs)
        out.append((np.array(X), evs))
    return out


class SearcherContract:
    """Tests every searcher must pass (subclass it as ``TestXxx``)."""

    searcher_cls: ClassVar[type]
    cfg: ClassVar[dict] = {}
    batch: ClassVar[int] = 1
    golden_name: ClassVar[str] = ""
    golden_points: ClassVar[int] = 6
    golden_atol: ClassVar[float] = 1e-6
    #: folder of the golden files; None: ``golden/`` next to the subclass's test module
    golden_dir: ClassVar[Optional[Path]] = None

    def make_task(self) -> Any:  # pragma: no cover - abstract
        raise NotImplementedError

    def make(self, seed: int = 0, **over: Any) -> tuple[Any, Any]:
        task = self.make_task()
        return self.searcher_cls(task.problem(), dict(self.cfg, **over), seed), task

    def test_asks_in_bounds_with_batch_sizes(self, tmp_path: Path) -> None:
        s, task = self.make()
        space = task.problem().space
        batches = run_batches(s, task, self.batch, seed=0, workdir=tmp_path)
        assert batches
        for X, _ in batches:
            assert X.ndim == 2 and X.shape[1] == space.dim
            assert 1 <= len(X) <= self.batch
            assert np.all(X >= np.array(space.lows)) and np.all(X <= np.array(space.highs))

    def test_finished_after_budget(self, tmp_path: Path) -> None:
        s, task = self.make()
        batches = run_batches(s, task, self.batch, seed=0, workdir=tmp_path)
        n = sum(len(X) for X, _ in batches)
        assert s.finished()
        assert n <= self.cfg["budget"]
        converged = getattr(s, "_converged", None)  # a searcher's own stopping rule, if it has one
        assert n == self.cfg["budget"] or (converged is not None and converged())
        assert s.ask(self.batch).shape == (0, task.problem().space.dim)

    def test_same_seed_same_points(self, tmp_path: Path) -> None:
        a, task = self.make(seed=3)
        b, _ = self.make(seed=3)
        c, _ = self.make(seed=4)
        xa = np.vstack([X for X, _ in run_batches(a, task, self.batch, seed=3, workdir=tmp_path)])
        np.random.seed(123)  # global numpy state must not matter
        xb = np.vstack([X for X, _ in run_batches(b, task, self.batch, seed=3, workdir=tmp_path)])
        xc = np.vstack([X for X, _ in run_batches(c, task, self.batch, seed=4, workdir=tmp_path)])
        np.testing.assert_array_equal(xa, xb)
        assert xa.shape != xc.shape or not np.allclose(xa, xc)

    def test_replay_resume_gives_the_next_points(self, tmp_path: Path) -> None:
        full, task = self.make(seed=1)
        batches = run_batches(full, task, self.batch, seed=1, workdir=tmp_path)
        assert len(batches) >= 2
        cut = len(batches) // 2
        resumed, _ = self.make(seed=1)
        for X, evs in batches[:cut]:  # what the runner does on resume: replay the recorded history
            np.testing.assert_allclose(resumed.ask(self.batch), X, rtol=0, atol=1e-12)
            resumed.tell(X, evs)
        np.testing.assert_allclose(resumed.ask(self.batch), batches[cut][0], rtol=0, atol=1e-12)

    def test_tell_rejects_points_it_did_not_ask(self, tmp_path: Path) -> None:
        s, task = self.make()
        X = s.ask(self.batch)
        evs = [task.evaluate(task.problem().space.to_dict(x), EvalContext(i, i, tmp_path)) for i, x in enumerate(X)]
        Y = X.copy()
        Y[0, 0] += 1e-3 if Y[0, 0] + 1e-3 <= task.problem().space.highs[0] else -1e-3
        with pytest.raises(ValueError):
            s.tell(Y, evs)

    def test_summary_goes_to_hdf5(self, tmp_path: Path) -> None:
        from toolkit.store import h5

        s, task = self.make()
        run_batches(s, task, self.batch, seed=0, workdir=tmp_path)
        summary = s.summary()
        assert summary
        path = h5.write(tmp_path / "search.h5", {"searcher": summary})
        back = h5.read(path)["searcher"]
        assert set(back) == set(summary)
        for k, v in summary.items():
            if np.asarray(v).dtype.kind in "fiub":
                np.testing.assert_array_equal(np.asarray(back[k]), np.asarray(v))

    def test_golden_points(self, tmp_path: Path) -> None:
        if not self.golden_name:
            pytest.skip("no golden file for this searcher")
        s, task = self.make(seed=0)
        X = np.vstack([X for X, _ in run_batches(s, task, self.batch, seed=0, workdir=tmp_path)])[: self.golden_points]
        folder = self.golden_dir or Path(inspect.getfile(type(self))).parent / "golden"
        path = Path(folder) / f"{self.golden_name}.json"
        if os.environ.get("JT_REGEN_GOLDEN"):
            path.write_text(json.dumps({
                "searcher": self.searcher_cls.__name__,
                "cfg": self.cfg,
                "batch": self.batch,
                "seed": 0,
                "points": X.tolist(),
                "regenerate": f"JT_REGEN_GOLDEN=1 python -m pytest <tests>/{Path(inspect.getfile(type(self))).name} -k golden",
            }, indent=1) + "\n")
        golden = json.loads(path.read_text())
        assert golden["cfg"] == self.cfg, "config changed: regenerate the golden file"
        np.testing.assert_allclose(X, np.array(golden["points"]), rtol=0, atol=self.golden_atol)
