"""Find an artifact from what a user typed: an MLflow run id, a folder holding it, or the file.

``task.init=`` (Stage 2), ``task.takeoff_from=`` and ``action.prior=`` all name "the file that run
made" in one of three ways; ``resolve`` is the one place that turns such a reference into a path:

* a **file** (ends in ``.h5``, or exists as a file): that file;
* a **folder** (contains ``/``, or exists as a folder): ``<folder>/<artifact>``, else one folder
  down (``<folder>/*/<artifact>``), else (with ``accept``) any ``*.h5`` there or one folder down
  that ``accept`` takes, in sorted order. Never deeper: ``action.prior=/`` looks at ``/*.h5`` and
  ``/*/*.h5``, not at the whole filesystem;
* an MLflow **run id** in the store (``store``, ``$JT_STORE`` or ``./artifacts``):

  - a nested evaluation (it has the ``mlflow.parentRunId`` tag): that run's artifact;
  - an outer run and ``eval_index >= 0``: its nested evaluation with that ``jt.eval_index``;
  - an outer run: its own artifact if it has one (``search=single`` logs the evaluation on the
    run itself), else the best of its nested runs holding the artifact (``best_by``; ties and
    ``best_by=None`` go to the lower ``jt.eval_index``, then the earlier start).

  A run's artifact is looked for in its artifact folder as in a folder (one level down at most).

Every failure is one ``JtError`` line ``<what>=<ref>: <what is wrong>; <hint>``. Looking a run up
never creates a store: without ``<root>/mlflow.db`` the answer is "no such run".

``search_runs`` builds the MLflow filter strings of jt's run look-ups (tags, params, status) from
values, checked, in one place.
"""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path
from typing import Any, Callable, Mapping, Optional, Sequence, Union

from toolkit.errors import JtError

PARENT_TAG = "mlflow.parentRunId"
INDEX_TAG = "jt.eval_index"
_KEY = re.compile(r"^[A-Za-z0-9_.\- /]+$")  # what a tag / param key may be in a jt filter
BestBy = Union[Callable[[Any], Any], Sequence[str], None]


@dataclasses.dataclass(frozen=True)
class Resolved:
    """Where a reference led.

    Attributes:
        path: the artifact file (absolute).
        run: the MLflow ``Run`` holding it, None for a file or folder reference.
        run_id: that run's id (``""`` for a file or folder).
        eval_index: its ``jt.eval_index`` tag (-1 when it has none, or for a file or folder).
        folder: the folder holding ``path``.
    """

    path: Path
    run: Any = None
    run_id: str = ""
    eval_index: int = -1

    @property
    def folder(self) -> Path:
        """The folder holding ``path``."""
        return self.path.parent


def is_path(ref: str) -> bool:
    """Whether ``ref`` names a file or folder rather than a run id."""
    return "/" in ref or ref.endswith(".h5") or Path(ref).expanduser().exists()


def open_store(store: Any) -> Any:
    """The ``Store`` at ``store`` (``store_root`` rules), or None when it has no ``mlflow.db``.

    Unlike ``opening.open_store`` this never creates a store; an open ``Store`` is returned as it is.
    """
    from toolkit.store import opening
    from toolkit.store.tracking import Store, is_server_uri, store_root

    if isinstance(store, Store):
        return store
    root = store_root(store)
    if is_server_uri(root):  # a tracking server: it exists or the store says so in one line
        return opening.open_store(root)
    return opening.open_store(root) if (root / "mlflow.db").is_file() else None


def _quoted(value: Any) -> str:
    text = str(value)
    if "'" in text or "\\" in text:
        raise JtError(f"cannot search runs for the value {text!r} (it holds a quote or a backslash)")
    return f"'{text}'"


def search_runs(store: Any, experiment_ids: Sequence[str], *, tags: Optional[Mapping[str, Any]] = None,
                params: Optional[Mapping[str, Any]] = None, status: Optional[str] = None,
                max_results: int = 10000) -> list:
    """Runs of ``experiment_ids`` whose tags / params equal the given values (and with ``status``).

    Args:
        store: a ``toolkit.store.tracking.Store``.
        experiment_ids: experiments to search.
        tags: ``{key: value}`` the runs' tags must equal.
        params: ``{key: value}`` the runs' params must equal (compared as strings).
        status: ``FINISHED``, ``FAILED``, ``RUNNING``, ... or None for any.
        max_results: at most this many runs.
    """
    clauses = []
    for kind, items in (("tags", tags or {}), ("params", params or {})):
        for key, value in items.items():
            if not _KEY.match(str(key)):
                raise JtError(f"cannot search runs by the {kind[:-1]} {key!r}")
            clauses.append(f"{kind}.`{key}` = {_quoted(value)}")
    if status is not None:
        clauses.append(f"attributes.status = {_quoted(status)}")
    return store.client.search_runs(list(experiment_ids), filter_string=" and ".join(clauses),
                                    max_results=max_results)


def children(store: Any, run: Any) -> list:
    """The nested runs of ``run`` (those whose ``mlflow.parentRunId`` tag is its id)."""
    return search_runs(store, [run.info.experiment_id], tags={PARENT_TAG: run.info.run_id})


def eval_index_of(run: Any) -> int:
    """The ``jt.eval_index`` tag of ``run``, -1 when it has none."""
    try:
        return int(run.data.tags.get(INDEX_TAG, -1))
    except (TypeError, ValueError):
        return -1


def find_in(folder: Path, artifact: str, accept: Optional[Callable[[Path], bool]] = None) -> Optional[Path]:
    """``folder/artifact``, else ``folder/*/artifact``, else (``accept``) an accepted ``*.h5``; or None."""
    folder = Path(folder)
    if not folder.is_dir():
        return None
    if (folder / artifact).is_file():
        return folder / artifact
    below = sorted(p for p in folder.glob(f"*/{artifact}") if p.is_file())
    if below:
        return below[0]
    if accept is not None:
        for p in sorted(folder.glob("*.h5")) + sorted(folder.glob("*/*.h5")):
            if p.is_file() and accept(p):
                return p
    return None


def run_config(artifact: Any, config: Optional[str] = None) -> Path:
    """The ``config.yaml`` of the run that wrote ``artifact``: ``config`` if given, else the one in
    the artifact's folder or the folder above (a run's artifacts and its work folder both hold one).

    Raises:
        JtError: one line: ``config`` is not a file, or no config.yaml beside ``artifact``.
    """
    if config is not None:
        if not Path(config).is_file():
            raise JtError(f"--config={config}: no such file")
        return Path(config)
    for folder in Path(artifact).parents[:2]:
        if (folder / "config.yaml").is_file():
            return folder / "config.yaml"
    raise JtError(f"no config.yaml beside {artifact} (the run's work folder); pass --config")


def _key_of(best_by: BestBy) -> Callable[[Any], Any]:
    """A sort key (larger is better) of a run from ``best_by`` (a function, or metric names)."""
    if callable(best_by):
        return best_by

    def metrics(run: Any) -> tuple:
        m = run.data.metrics
        vals = [float(m.get(k, -math.inf)) for k in best_by]
        return tuple(-math.inf if math.isnan(v) else v for v in vals)

    return metrics


def resolve(ref: str, *, artifact: str, store: Any = None, best_by: BestBy = None,
            eval_index: int = -1, what: str = "task.init", label: str = "", hint: str = "",
            index_what: str = "", accept: Optional[Callable[[Path], bool]] = None) -> Resolved:
    """The artifact that ``what=ref`` names (see the module docstring).

    Args:
        ref: a run id, a folder or a file.
        artifact: the artifact's file name (``ppo.h5``, ``takeoff_state.h5``, ``prior.h5``).
        store: the store to look run ids up in: a path (``store_root`` rules: None is ``$JT_STORE``
            or ``./artifacts``) or an open ``Store``.
        best_by: which nested run of an outer run is best: a function of the MLflow ``Run``
            (larger is better) or metric names (compared in order, larger is better, a missing
            or NaN metric is the worst); None: the lowest ``jt.eval_index``.
        eval_index: for an outer run, take its nested evaluation with this ``jt.eval_index``.
        what: the setting being resolved, for the messages (``task.init``).
        label: what the artifact is, for the messages (``trained policy``); default its name.
        hint: what to do, ending every message (``make one with: jt run task=runup``).
        index_what: the setting ``eval_index`` came from, for its messages (``task.init_eval``).
        accept: also take any ``*.h5`` this returns True for when ``artifact`` itself is absent.

    Raises:
        JtError: one line naming ``what=ref``, what is wrong and ``hint``.
    """
    ref = str(ref).strip()
    tail = f"; {hint}" if hint else ""

    def fail(msg: str) -> JtError:
        return JtError(f"{what}={ref}: {msg}{tail}")

    if not ref:
        raise fail(f"empty; give a run id, or a folder holding {artifact} (or the file)")
    if is_path(ref):
        p = Path(ref).expanduser()
        if p.suffix == ".h5" or p.is_file():
            if not p.is_file():
                raise fail("no such file")
            return Resolved(path=p.resolve())
        found = find_in(p, artifact, accept)
        if found is None:
            raise fail(f"no {artifact} there (looked in {p} and one folder down)")
        return Resolved(path=found.resolve())
    return _from_run(ref, artifact, store, _key_of(best_by) if best_by is not None else None, eval_index,
                     label or artifact, index_what or "eval index", accept, fail)


def _from_run(ref: str, artifact: str, store: Any, key: Optional[Callable[[Any], Any]], eval_index: int,
              label: str, index_what: str, accept: Optional[Callable[[Path], bool]],
              fail: Callable[[str], JtError]) -> Resolved:
    """``resolve`` for a run id (``key``: larger is better; None: the lowest evaluation index)."""
    from toolkit.store.tracking import store_root

    st = open_store(store)
    if st is None:
        raise fail(f"no such run: not a file or folder either, and there is no store at {store_root(store)}")
    try:
        run = st.client.get_run(ref)
    except Exception:  # noqa: BLE001 - MLflow raises its own exception types for unknown ids
        raise fail(f"no such run in store {st.root} (and not a file or folder)") from None
    missing = f"no {label} (no {artifact} artifact)" if label != artifact else f"no {artifact} artifact"

    def holding(r: Any) -> Optional[Resolved]:
        f = find_in(st.artifact_dir(r.info.run_id), artifact, accept)
        return None if f is None else Resolved(path=f, run=r, run_id=r.info.run_id, eval_index=eval_index_of(r))

    nested = PARENT_TAG in run.data.tags
    if nested or eval_index < 0:  # a nested evaluation, or an outer run holding the artifact itself
        got = holding(run)
        if got is not None:
            return got
        if nested:
            raise fail(f"run {ref} has {missing}")
    kids = children(st, run)
    if eval_index >= 0:
        by_index = {eval_index_of(k): k for k in kids if INDEX_TAG in k.data.tags}
        if not by_index:
            raise JtError(f"{index_what}={eval_index}: run {ref} has no nested evaluations; leave it at -1")
        if eval_index not in by_index:
            raise JtError(f"{index_what}={eval_index}: run {ref} has evaluations {sorted(by_index)}; "
                          "choose one of them")
        got = holding(by_index[eval_index])
        if got is None:
            raise fail(f"its evaluation {eval_index} (run {by_index[eval_index].info.run_id}) has {missing}")
        return got
    found = [r for r in (holding(k) for k in kids) if r is not None]
    if not found:
        raise fail(f"run {ref} has {missing}" + (f", nor has any of its {len(kids)} nested runs" if kids else ""))
    if key is None:
        return min(found, key=lambda r: (r.eval_index, r.run.info.start_time))
    return max(found, key=lambda r: (key(r.run), -r.eval_index, -r.run.info.start_time))
