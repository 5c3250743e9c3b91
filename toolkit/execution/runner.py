"""``jt run``: one outer MLflow run driving a searcher over a task, evaluations as nested runs.

Flow: start (or reopen, for ``resume=RUN_ID``) the outer run, owned by this process, and log config,
seed, version and commit (``toolkit.execution.lifecycle``: the config is saved before the run's row
exists, and a second process resuming a live run is refused) → build searcher and replay the saved
history → loop ``ask`` → evaluate the batch through the executor (each point a nested run, its
files logged as HDF5/PNG artifacts) → save the history → ``tell`` → finally log the task's summary
metrics and the search HDF5. Ctrl-C or SIGTERM ends the run as KILLED with the reason, an
exception as FAILED, a full disk in one line; a resumed run continues from the last completed
evaluation, and an evaluation cut off mid-way finds its own checkpoint in its workdir.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path
from typing import Any, Optional, Sequence

import numpy as np

from toolkit import plugins
from toolkit.errors import JtError
from toolkit.execution import describe, lifecycle, progress, provenance, stopping
from toolkit.execution.evaluate import Job, run_job
from toolkit.execution.history import History, Record
from toolkit.execution.seeds import derive
from toolkit.interfaces import EvalContext, Evaluation
from toolkit.store import h5
from toolkit.store.tracking import Store, store_root
from toolkit.store.opening import open_store


@dataclasses.dataclass
class RunResult:
    """What ``run`` returns.

    Attributes:
        run_id: the outer MLflow run.
        store: the store it lives in.
        metrics: the outer run's final metrics.
        evaluations: every evaluation, in order.
    """

    run_id: str
    store: Store
    metrics: dict[str, float]
    evaluations: list[Evaluation]


def _log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def _eval_metrics(ev: Evaluation, names: list[str]) -> dict[str, float]:
    out = {k: float(v) for k, v in ev.metrics.items()}
    for i, f in enumerate(ev.features):
        out[f"feature_{i}"] = float(f)
    for i, o in enumerate(ev.objectives):
        out[f"objective_{names[i] if i < len(names) else i}"] = float(o)
    out["failed"] = float(ev.failed)
    return out


_Terminate = stopping.Terminate  #: SIGTERM: a stop at the next safe point (``stopping``)


def _train_prior(store: Any, overrides: Sequence[str], tag: str) -> str:
    """Train an action space's prior into ``store`` (``jt run <overrides>``, ``toolkit.priors.auto``); its run id."""
    from toolkit.config import compose

    return run(compose([*overrides, f"store={store.root}"])).run_id


def preflight(cfg: Any) -> tuple[Any, Any, Any, Any, Any]:
    """Every check of a composed config that needs its plugins, before anything is trained or a run
    row opens: the task's own (``problem()``) and the searcher's with that problem (a task without
    objectives for rmoo, a constraint it cannot keep). ``jt compare`` runs it on every cell first.

    Returns:
        ``(task_cls, search_cls, exec_cls, task, problem)``.

    Raises:
        JtError: one line, what is wrong with this config.
    """
    task_cls = plugins.load("task", str(cfg.task.name))
    search_cls = plugins.load("search", str(cfg.search.name))
    exec_cls = plugins.load("executor", str(cfg.executor.name))
    task = task_cls(cfg)
    problem = task.problem()  # the task's own checks, before a prior is trained or a run opens
    search_cls(problem, cfg.search, int(cfg.seed))  # and the searcher's (a task without objectives for rmoo)
    return task_cls, search_cls, exec_cls, task, problem


def run(cfg: Any, command: Optional[str] = None) -> RunResult:
    """Run a composed, validated config (see ``toolkit.config.compose``) to completion.

    Args:
        cfg: the config.
        command: the command that reproduces the run, for its description (default: this
            process's command line).
    """
    from omegaconf import OmegaConf

    from toolkit.priors import auto as auto_prior

    task_cls, search_cls, exec_cls, task, problem = preflight(cfg)
    if cfg.get("cost"):  # what the wait costs, before any work (a prior trained first included)
        _log(f"jt: cost: {cfg.cost}")
    auto = auto_prior.wants_auto(cfg)
    cfg = auto_prior.resolve(cfg, _train_prior)  # action.prior=auto: the store's own prior, trained on first use
    if auto:  # the task's checks that need the prior (a task.evaluate policy's fit), before the run opens
        task_cls.check_run(cfg)
    store = open_store(store_root(str(cfg.store)))
    experiment = str(cfg.task.name)
    nested = bool(getattr(search_cls, "nested", True))
    container = OmegaConf.to_container(cfg, resolve=True)

    command = command or provenance.command_line()
    with _Terminate():  # SIGTERM while opening: the run is left as it was, resumable
        try:
            run_id, resumed, lock = lifecycle.open_run(store, cfg, experiment, command, task_cls, nested)
        except Exception as e:  # a full disk once the run exists: open_run says how to resume it
            if not isinstance(e, JtError) and lifecycle.disk_full(e):
                raise JtError(f"store={store.root}: no space left to start a run ({lifecycle.disk_full(e)}); "
                              "free some and run it again") from e
            raise
        try:
            return _drive(store, cfg, command, run_id, resumed, task, problem, search_cls, exec_cls, container,
                          experiment, nested)
        finally:
            lock.release()


def _drive(store: Store, cfg: Any, command: str, run_id: str, resumed: bool, task: Any, problem: Any,
           search_cls: Any, exec_cls: Any, container: dict, experiment: str, nested: bool) -> RunResult:
    """Run the opened (and locked) outer run to its end: FINISHED, KILLED or FAILED."""
    names = problem.space.names
    workdir = store.workdir(run_id)
    hist_path = workdir / "search_history.h5"
    _log(f"jt: run {run_id} ({experiment}){' resumed' if resumed else ''}; store {store.root}")
    try:
        history = History.load(hist_path, names)
        if resumed:
            lifecycle.close_stale_children(store, run_id, experiment, {r.index for r in history.records})
        searcher = search_cls(problem, cfg.search, int(cfg.seed))
        _replay(searcher, history, int(searcher.batch_size))
        if resumed and len(history):
            _log(f"jt: resumed after {len(history)} completed evaluation(s)")
        executor = exec_cls(cfg.executor)
        try:
            files = _search_loop(store, cfg, container, run_id, experiment, task, searcher, history,
                                 names, problem, nested, executor, hist_path, cfg.get("run_name") or "")
        finally:
            executor.close()
        stopping.check()  # a safe point: every evaluation is in the store, the summary not yet
        metrics, pictures, table = _finish(store, run_id, task, searcher, history, workdir, hist_path, nested)
        pictures += files  # search=single: the evaluation's own files are on this run
        note = describe.outer(cfg, command, metrics, getattr(task, "key_metrics", ()), pictures, nested,
                              describe.table(*table) if table else "")
        store.set_tags(run_id, {describe.NOTE: note})
        store.end_run(run_id, "FINISHED")
    except KeyboardInterrupt as e:
        try:  # evaluations it cut off: KILLED now (as a resume would), so nothing is left RUNNING
            lifecycle.close_stale_children(store, run_id, experiment,
                                           {r.index for r in History.load(hist_path, names).records})
        except Exception:  # noqa: BLE001 - the resume closes them too; the run's own end comes first
            pass
        store.end_run(run_id, "KILLED", str(e) or "interrupted (Ctrl-C)")
        _log(f"jt: run {run_id} interrupted; continue it with: jt run resume={run_id} store={store.root}")
        raise
    except BaseException as e:
        marked = _end_failed(store, run_id, e)
        full = lifecycle.disk_full(e)
        if full:  # one line; the run stays resumable (RUNNING, or FAILED if that could still be written)
            raise lifecycle.stopped_by_full_disk(run_id, store, full) from e
        if not marked:
            _log(f"jt: could not mark run {run_id} FAILED in the store; it still shows RUNNING")
        raise
    return RunResult(run_id, store, metrics, history.evaluations())


def _end_failed(store: Store, run_id: str, exc: BaseException) -> bool:
    """Mark the run FAILED with the error; False when the store cannot be written (a full disk)."""
    try:
        store.end_run(run_id, "FAILED", f"{type(exc).__name__}: {exc}")
        return True
    except Exception:  # noqa: BLE001 - the run's own error is the one to report
        return False


def _replay(searcher: Any, history: History, batch: int) -> None:
    for b in range(history.n_batches):
        recs = history.batch(b)
        x = np.asarray(searcher.ask(batch), dtype=float)
        got = np.stack([r.x for r in recs]) if recs else np.zeros((0, x.shape[-1] if x.ndim == 2 else 0))
        n = min(len(x), len(got))
        if n == 0 or not np.allclose(x[:n], got[:n], rtol=1e-9, atol=1e-12):
            raise JtError("cannot resume: the searcher does not repeat its recorded points "
                          "(config or code changed since the run started)")
        searcher.tell(x[:n], [r.evaluation for r in recs[:n]])


def _search_loop(store: Store, cfg: Any, container: dict, run_id: str, experiment: str, task: Any,
                 searcher: Any, history: History, names: list[str], problem: Any, nested: bool,
                 executor: Any, hist_path: Path, parent_name: str) -> list[str]:
    """Ask, evaluate, log and tell until the budget is spent; the files logged on the outer run
    itself (by a searcher that is not ``nested``). Progress: one ``progress.RunProgress`` for the
    run, fed directly by evaluations in this process and through the executor's queue by those in
    its workers."""
    budget = int(cfg.search.budget)
    obj_names = list(problem.objective_names)
    parent_name = parent_name or store.get_run(run_id).info.run_name
    prefix = str(getattr(task, "curve_prefix", "train/"))
    on_outer: list[str] = []
    bar = progress.RunProgress(budget, len(history), f"task={experiment}")
    pump = None
    try:
        while not searcher.finished() and len(history) < budget:
            stopping.check()  # a safe point: between batches
            x = np.asarray(searcher.ask(min(int(searcher.batch_size), budget - len(history))), dtype=float)
            if len(x) == 0:  # a task with no parameters still has one (empty) point
                break
            b, start = history.n_batches, len(history)
            channel: Any = bar.update  # evaluations in this process report straight to the bar
            if not executor.runs_inline(len(x)):  # in worker processes: through the executor's queue
                q = executor.progress_queue()
                channel = progress.Channel(q) if q is not None else None
                if q is not None and pump is None:
                    pump = bar.pump(q)
            jobs, child_ids = [], []
            for j, xi in enumerate(x):
                idx = start + j
                point = problem.space.to_dict(xi)
                ctx = EvalContext(index=idx, seed=derive(int(cfg.seed), idx),
                                  workdir=store.workdir(run_id, f"eval_{idx:04d}"))
                child = run_id
                if nested:
                    child = store.start_run(experiment, run_name=f"eval-{idx:04d}", parent_run_id=run_id,
                                            tags={"jt.eval_index": str(idx), "jt.seed": str(ctx.seed)})
                    store.log_params(child, {**point, "seed": ctx.seed})
                child_ids.append(child)
                jobs.append(Job(container, point, ctx, verbose=True, channel=channel))
            evs: list[Optional[Evaluation]] = [None] * len(jobs)
            for j, (ev, secs) in executor.imap(run_job, jobs):
                evs[j] = ev
                logged = _log_evaluation(store, child_ids[j], ev, jobs[j].ctx.workdir, obj_names, secs, prefix)
                if not nested:
                    on_outer += logged
                history.add(Record(start + j, b, x[j], ev, child_ids[j] if nested else ""))
                if nested:
                    ctx = jobs[j].ctx
                    store.set_tags(child_ids[j], {describe.NOTE: describe.evaluation(
                        ctx.index, parent_name, jobs[j].point, ctx.seed, ev.metrics,
                        getattr(task, "key_metrics", ()), logged, ev.reason if ev.failed else "")})
                    store.end_run(child_ids[j], "FINISHED")
                shown = ", ".join(f"{k}={v:.4g}" for k, v in list(ev.metrics.items())[:4])
                bar.finished(start + j, f"jt: [{len(history)}/{budget}] eval {start + j} in {secs:.1f}s"
                                        f"{' FAILED: ' + ev.reason if ev.failed else ''} {shown}")
                stopping.check()  # a safe point: this evaluation is in the store
            history.save(hist_path)
            searcher.tell(x, evs)
    finally:
        if pump is not None:
            pump.stop()
        bar.close()
    return on_outer


def curve_key(key: str, prefix: str = "train/") -> str:
    """The MLflow key of an evaluation's curve ``key``: ``prefix + key`` unless ``key`` already has
    a namespace (``/``), so a curve never shares its key with the final value of the same name."""
    return key if "/" in key else f"{prefix}{key}"


def _points(series: Any) -> Any:
    """``(step, value, unix_seconds | None)`` of a curve's points (``(step, value)`` or with a time)."""
    for point in series:
        step, value, *rest = point
        yield int(step), float(value), (float(rest[0]) if rest and rest[0] is not None else None)


def _log_evaluation(store: Store, run_id: str, ev: Evaluation, workdir: Path, obj_names: list[str],
                    secs: float, prefix: str = "train/") -> list[str]:
    """Log an evaluation's finals (step 0), curves (``train/<key>``) and files; the files' names."""
    with store.metrics(run_id) as buf:
        buf.add_many({**_eval_metrics(ev, obj_names), "eval_seconds": secs})
        for key, series in ev.history.items():
            for step, value, when in _points(series):
                buf.add(curve_key(key, prefix), value, step, when)
    if ev.failed:
        store.set_tags(run_id, {"jt.failure": ev.reason or "failed"})
    if ev.artifacts is None:
        store.log_artifacts(run_id, workdir)
        return [str(p.relative_to(workdir)) for p in sorted(Path(workdir).rglob("*")) if p.is_file()]
    for name in ev.artifacts:
        store.log_artifact(run_id, workdir / name)
    return list(ev.artifacts)


def _finish(store: Store, run_id: str, task: Any, searcher: Any, history: History, workdir: Path,
            hist_path: Path, nested: bool) -> tuple[dict[str, float], list[str], Optional[tuple[list, list]]]:
    """Log the run's summary: metrics, curves, files, the task's summary pictures and table.

    Returns:
        ``(metrics, picture artifact names, (header, rows) of the summary table or None)``.
    """
    evs = history.evaluations()
    out_dir = workdir / "summary"
    out_dir.mkdir(exist_ok=True)
    summary = task.summarize(evs, out_dir) or {}
    curves = {k: v for k, v in summary.items() if not isinstance(v, (int, float))}
    metrics = {k: float(v) for k, v in summary.items() if k not in curves}
    metrics["n_evaluations"] = float(len(evs))
    metrics["n_failed"] = float(sum(e.failed for e in evs))
    if nested and evs:
        for key in getattr(task, "key_metrics", ()):
            vals = [e.metrics[key] for e in evs if key in e.metrics and not math.isnan(e.metrics[key])]
            if vals and key not in metrics:
                metrics[f"best_{key}"] = float(max(vals))
    # search=single logged its evaluation on this run, and a run killed in here logged some already:
    # a value of the same name is not logged twice
    logged = set(store.get_run(run_id).data.metrics)
    with store.metrics(run_id) as buf:
        buf.add_many({k: v for k, v in metrics.items() if k not in logged})
        for key, points in curves.items():  # run-level curves: [(step, value[, unix_s]), ...]
            if key in logged:  # a run killed in here logged it already
                continue
            for step, value, when in _points(points):
                buf.add(key, value, step, when)
    if not nested:  # the evaluations were logged on this run: report their metrics as the run's
        for e in evs:
            metrics = {**{k: float(v) for k, v in e.metrics.items()}, **metrics}
    table = _summary_table(task, evs, out_dir)
    h5.write(out_dir / "search.h5", {"history": history.arrays(), "searcher": searcher.summary() or {}},
             attrs={"format": "jt.search/1"})
    history.save(hist_path)
    store.log_artifacts(run_id, out_dir)
    store.log_artifact(run_id, hist_path)
    pictures = _summary_artifacts(store, run_id, task, evs, workdir / "pictures")
    pictures += [str(p.relative_to(out_dir)) for p in sorted(out_dir.rglob("*"))
                 if p.suffix.lower() in describe.PICTURES]
    return metrics, pictures, table


def _summary_artifacts(store: Store, run_id: str, task: Any, evs: list[Evaluation], folder: Path) -> list[str]:
    """Call the task's ``summary_artifacts`` hook and log what it returns on the outer run (files in
    ``folder`` keep their sub-folder); the artifact names. A path that is no file is skipped, said."""
    hook = getattr(task, "summary_artifacts", None)
    if hook is None:
        return []
    folder.mkdir(parents=True, exist_ok=True)
    names = []
    for p in hook(evs, folder) or []:
        p = Path(p)
        if not p.is_file():
            _log(f"jt: warning: {type(task).__name__}.summary_artifacts returned {p}, which is not a file; not logged")
            continue
        try:
            sub = p.resolve().parent.relative_to(folder.resolve())
        except ValueError:
            sub = Path(".")
        store.log_artifact(run_id, p, None if str(sub) == "." else str(sub))
        names.append(str(sub / p.name) if str(sub) != "." else p.name)
    return names


def _summary_table(task: Any, evs: list[Evaluation], out_dir: Path) -> Optional[tuple[list, list]]:
    """The task's ``summary_table`` (``(header, rows)`` or None), written to ``summary_table.json``."""
    import json

    hook = getattr(task, "summary_table", None)
    got = hook(evs) if hook is not None else None
    if not got:
        return None
    header, rows = got
    header = [str(h) for h in header]
    rows = [[v if isinstance(v, (int, float, str, bool)) or v is None else str(v) for v in row] for row in rows]
    bad = [i for i, row in enumerate(rows) if len(row) != len(header)]
    if bad:  # a plugin's slip must not fail a finished search: say it, show no table
        _log(f"jt: warning: {type(task).__name__}.summary_table: row {bad[0]} has {len(rows[bad[0]])} cells "
             f"for {len(header)} columns; no summary table")
        return None
    (out_dir / "summary_table.json").write_text(json.dumps({"header": header, "rows": rows}, indent=1,
                                                           allow_nan=True))
    return header, rows
