"""The search history: every evaluated point and what it measured, saved after every tell.

It is the resumable state of a search: a resumed run rebuilds its searcher from the seed and
replays the history through ``ask``/``tell``, so nothing already evaluated is evaluated again. It
is written atomically to ``<workdir>/search_history.h5`` and logged as the outer run's artifact.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from toolkit.interfaces import Evaluation
from toolkit.store import h5


@dataclasses.dataclass
class Record:
    """One finished evaluation.

    Attributes:
        index: evaluation number.
        batch: which ask it came from.
        x: the point ``(dim,)``.
        evaluation: what it returned.
        run_id: its nested MLflow run ('' when evaluated in the outer run).
    """

    index: int
    batch: int
    x: np.ndarray
    evaluation: Evaluation
    run_id: str = ""


class History:
    """Ordered records of a search, grouped by ask (batch)."""

    def __init__(self, names: Sequence[str]) -> None:
        self.names = list(names)
        self.records: list[Record] = []

    def __len__(self) -> int:
        return len(self.records)

    @property
    def n_batches(self) -> int:
        return 1 + max((r.batch for r in self.records), default=-1)

    def batch(self, b: int) -> list[Record]:
        """Records of ask number ``b``, in index order."""
        return sorted((r for r in self.records if r.batch == b), key=lambda r: r.index)

    def add(self, record: Record) -> None:
        self.records.append(record)

    def evaluations(self) -> list[Evaluation]:
        """Every evaluation in index order, each with its ``run_id``."""
        out = []
        for r in sorted(self.records, key=lambda r: r.index):
            r.evaluation.run_id = r.evaluation.run_id or r.run_id
            out.append(r.evaluation)
        return out

    # ---- persistence -----------------------------------------------------------------------
    def arrays(self) -> dict[str, Any]:
        """Columns as arrays (NaN where an evaluation lacks a value)."""
        recs = sorted(self.records, key=lambda r: r.index)
        n = len(recs)
        dim = len(self.names)
        nf = max((len(r.evaluation.features) for r in recs), default=0)
        no = max((len(r.evaluation.objectives) for r in recs), default=0)
        keys = sorted({k for r in recs for k in r.evaluation.metrics})

        def fill(get: Any, width: int) -> np.ndarray:
            a = np.full((n, width), np.nan)
            for i, r in enumerate(recs):
                v = np.asarray(get(r), dtype=float).ravel()
                a[i, : v.size] = v
            return a

        return {
            "names": np.array(self.names, dtype="S"),
            "index": np.array([r.index for r in recs], dtype=np.int64),
            "batch": np.array([r.batch for r in recs], dtype=np.int64),
            "x": fill(lambda r: r.x, dim),
            "features": fill(lambda r: r.evaluation.features, nf),
            "objectives": fill(lambda r: r.evaluation.objectives, no),
            "failed": np.array([r.evaluation.failed for r in recs], dtype=bool),
            "reason": np.array([r.evaluation.reason for r in recs], dtype="S"),
            "run_id": np.array([r.run_id for r in recs], dtype="S"),
            "metrics": {k: np.array([r.evaluation.metrics.get(k, math.nan) for r in recs], dtype=float) for k in keys},
        }

    def save(self, path: Path) -> None:
        """Write atomically (an interruption leaves the previous complete file)."""
        h5.write(path, self.arrays(), attrs={"format": "jt.search_history/1"})

    @classmethod
    def load(cls, path: Path, names: Sequence[str]) -> "History":
        """Read a saved history, or an empty one if ``path`` does not exist."""
        hist = cls(names)
        if not Path(path).is_file():
            return hist
        d = h5.read(path)
        metrics = d.get("metrics", {})
        for i in range(len(d["index"])):
            feats = d["features"][i]
            objs = d["objectives"][i]
            ev = Evaluation(
                metrics={k: float(v[i]) for k, v in metrics.items() if not math.isnan(float(v[i]))},
                features=[float(v) for v in feats[~np.isnan(feats)]],
                objectives=[float(v) for v in objs[~np.isnan(objs)]],
                failed=bool(d["failed"][i]),
                reason=str(d["reason"][i]),
            )
            x = np.asarray(d["x"][i], dtype=float)
            ev.point = {n: float(v) for n, v in zip(names, x)}
            hist.add(Record(int(d["index"][i]), int(d["batch"][i]), x, ev, str(d["run_id"][i])))
        return hist

