"""``jt compare``: a grid of variants × seeds, then one table and one comparison run.

Every grid cell is an ordinary ``jt run`` (its own outer MLflow run, tagged as a child of the
comparison run). All cells are composed and checked before anything runs, so a typo in one
variant costs nothing. Cells run through the configured executor; a parallel executor runs each
cell with a one-process executor inside, so cores are not oversubscribed.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import sys
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from toolkit.errors import JtError
from toolkit.execution import describe, provenance
from toolkit.execution.runner import _Terminate


@dataclasses.dataclass
class CompareResult:
    """Attributes: table (printable), run_id (the comparison run), store_root, rows."""

    table: str
    run_id: str
    store_root: Path
    rows: list[dict[str, Any]]


def split_values(values: str, whole: str = "") -> list[str]:
    """The values of one ``--vary``, split at the commas outside brackets and quotes:
    ``"[30,60],[600]"`` → ``["[30,60]", "[600]"]``, ``"'a,b',c"`` → ``["'a,b'", "c"]``.

    Raises:
        JtError: an unclosed bracket or quote (one line naming the ``--vary``).
    """
    items, depth, quote, start = [], 0, "", 0
    pairs = {"[": "]", "{": "}", "(": ")"}
    closing: list[str] = []
    for i, ch in enumerate(values):
        if quote:
            quote = "" if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch in pairs:
            closing.append(pairs[ch])
        elif ch in ")]}":
            if not closing or closing.pop() != ch:
                raise JtError(f"bad --vary '{whole or values}': unmatched '{ch}'")
        elif ch == "," and not closing:
            items.append(values[start:i])
            start = i + 1
        depth = len(closing)
    if quote or depth:
        raise JtError(f"bad --vary '{whole or values}': unclosed {quote or closing[-1]!r}")
    items.append(values[start:])
    return items


def parse_vary(vary: Sequence[str]) -> list[tuple[str, list[str]]]:
    """``["spd=df,maba"]`` → ``[("spd", ["df", "maba"])]``; list and dict values keep their inner
    commas (``task.rates_hz=[30,60],[600]``)."""
    out = []
    for v in vary:
        if "=" not in v or not v.split("=", 1)[1]:
            raise JtError(f"bad --vary '{v}': expected KEY=a,b[,c]")
        key, values = v.split("=", 1)
        items = [s.strip() for s in split_values(values, v) if s.strip()]
        if not items:
            raise JtError(f"bad --vary '{v}': no values (expected KEY=a,b[,c])")
        if len(set(items)) != len(items):
            raise JtError(f"bad --vary '{v}': a value is repeated")
        if key.strip() in ("store", "resume"):
            raise JtError(f"bad --vary '{v}': a comparison and its runs live in one store and start fresh; "
                          f"give store=PATH once (resume a cell with jt run resume=RUN_ID)")
        out.append((key.strip(), items))
    return out


def _cell(args: tuple[list[str], bool]) -> tuple[str, dict[str, float]]:
    overrides, inner_serial = args
    from toolkit.config import compose
    from toolkit.execution.runner import run

    command = "jt run " + " ".join(overrides)  # what reruns this cell alone
    if inner_serial:  # every executor's group takes workers (ExecutorKeys); 1: one at a time
        overrides = [*overrides, "executor.workers=1"]
        # cells side by side in worker processes: plain progress lines (two live bars would
        # overwrite each other on one terminal); a cell run in the driver draws its bar
        import os

        os.environ["JT_PROGRESS"] = "lines"
    res = run(compose(overrides), command=command)
    return res.run_id, res.metrics


def metric_label(variant: str) -> str:
    """A variant as the first part of an MLflow metric key: ``search=bds`` → ``bds``, several keys
    ``a=1, b=x`` → ``1_x`` (MLflow keys allow letters, digits and ``_-. /:``)."""
    import re

    values = [part.split("=", 1)[-1] for part in variant.split(", ")]
    return re.sub(r"[^\w.\- :]", "_", "_".join(values)).strip() or "all"


def _params(overrides: Sequence[str], grid: list[tuple[str, list[str]]], seeds: int) -> dict[str, str]:
    """The comparison's params: each base override ``base.<key>``, each ``vary.<key>``, ``seeds``.

    Hydra's prefixes are not allowed in an MLflow key: ``~curriculum`` (delete a group) is
    ``base.curriculum = ~``, ``+key=v`` / ``++key=v`` are ``base.key = v``."""
    out = {}
    for o in overrides:
        key, value = (o.split("=", 1) + [""])[:2]
        if key.startswith("~"):
            key, value = key[1:], "~" + value
        out[f"base.{key.lstrip('+')}"] = value
    out.update({f"vary.{k}": ",".join(v) for k, v in grid})
    out["seeds"] = str(seeds)
    return out


def compare(overrides: Sequence[str], vary: Sequence[str], seeds: int) -> CompareResult:
    """Run every variant for ``seeds`` seeds and record the comparison."""
    from toolkit import plugins
    from toolkit.config import compose
    from toolkit.store.tracking import store_root
    from toolkit.store.opening import open_store

    if seeds < 1:
        raise JtError("--seeds must be at least 1")
    grid = parse_vary(vary)
    if not grid:
        raise JtError("nothing to compare: give --vary KEY=a,b (or --runs ID ID ...)")
    base = compose(list(overrides))
    keys = [k for k, _ in grid]
    variants = list(itertools.product(*[vals for _, vals in grid]))
    cells = []
    plain = [o for o in overrides if not o.split("=", 1)[0].lstrip("+~") == "seed"]
    for values in variants:
        chosen = dict(zip(keys, values))
        if "seed" in chosen:  # the variant's seed is where its seeds start (it is what it says)
            try:
                first = int(chosen.pop("seed"))
            except ValueError:
                raise JtError(f"--vary seed=...: seeds are integers, got {dict(zip(keys, values))['seed']!r}") from None
        else:
            first = int(base.seed)
        for s in range(seeds):
            ov = [*plain, *(f"{k}={v}" for k, v in chosen.items()), f"seed={first + s}"]
            cfg = compose(ov)  # check every cell before running any
            cells.append((values, ov, cfg))
    from toolkit.execution.runner import preflight

    for values, ov, cfg in cells:  # and what the cell's plugins check, before a compare row opens
        try:
            preflight(cfg)
        except JtError as e:
            raise JtError(f"cell {' '.join(ov)}: {e}") from None
    store = open_store(store_root(str(base.store)))
    task_cls = plugins.load("task", str(base.task.name))
    label = ", ".join(f"{k}={','.join(v)}" for k, v in grid)
    experiment = str(base.task.name)
    describe.ensure_experiment(store, experiment, task_cls)
    command = provenance.command_line() if provenance.command_line().startswith("jt compare") else \
        " ".join(["jt compare", *overrides, *(f"--vary {v}" for v in vary), f"--seeds {seeds}"])
    run_id = store.start_run(experiment, run_name=store.unique_run_name(experiment, f"compare {label} x{seeds}"),
                             tags={**describe.provenance_tags(command), "jt.compare": "true", "jt.vary": label,
                                   "jt.seeds": str(seeds), describe.NOTE: f"Comparison running: `{command}`\n"})
    terminate = _Terminate()  # SIGTERM ends the comparison run as KILLED, as Ctrl-C does (not left RUNNING)
    terminate.__enter__()
    try:
        store.log_params(run_id, _params(overrides, grid, seeds))
        executor = plugins.load("executor", str(base.executor.name))(base.executor)
        parallel = executor.n_workers > 1 and len(cells) > 1
        results: list[Any] = [None] * len(cells)
        try:
            done = 0
            for i, res in executor.imap(_cell, [(ov, parallel) for _, ov, _ in cells]):
                results[i] = res
                done += 1
                print(f"jt: compare: cell {done}/{len(cells)} done ({' '.join(cells[i][1])})", file=sys.stderr,
                      flush=True)
                values, _, cell_cfg = cells[i]
                variant = "·".join(f"{k}={v}" for k, v in zip(keys, values) if k != "seed")
                name = store.unique_run_name(experiment, f"{variant + '·' if variant else ''}seed={cell_cfg.seed}")
                store.set_tags(res[0], {"mlflow.parentRunId": run_id, "jt.compare_id": run_id,
                                        "mlflow.runName": name})
        finally:
            executor.close()
        per_cell = [(", ".join(f"{k}={v}" for k, v in zip(keys, values)), rid, m)
                    for (values, _, _), (rid, m) in zip(cells, results)]
        out = _record(store, run_id, per_cell, list(getattr(task_cls, "key_metrics", ())), label, command)
        store.end_run(run_id, "FINISHED")
        return out
    except KeyboardInterrupt as e:
        store.end_run(run_id, "KILLED", str(e) or "interrupted (Ctrl-C)")
        raise
    except BaseException as e:
        store.end_run(run_id, "FAILED", f"{type(e).__name__}: {e}")
        raise
    finally:
        terminate.__exit__(None, None, None)


def differing_params(params: Sequence[dict[str, str]]) -> list[str]:
    """The params that tell runs apart: those whose *set* values (``None`` or absent: the run's
    group has no such key) differ, seed and store excepted. When a group's ``name`` differs, its
    other keys count only where set values differ (``action=raw`` has no ``beta``: ``action.beta``
    tells ``cvae`` runs apart, not ``raw`` from ``cvae``)."""
    ignore = {"seed", "store", "resume", "run_name"}
    out = []
    for k in sorted(set().union(*params)):
        values = {p.get(k) for p in params if p.get(k) not in (None, "None")}
        if k not in ignore and (len(values) > 1 or (k.endswith(".name") and len({p.get(k) for p in params}) > 1)):
            out.append(k)
    return sorted(out, key=lambda k: (k.rsplit(".", 1)[0], not k.endswith(".name"), k))  # a group's name first


def variant_label(p: dict[str, str], differing: Sequence[str]) -> str:
    """``action=cvae, action.beta=1.0``: a run's differing params it has (``group.name`` as ``group``)."""
    parts = [f"{k[:-len('.name')] if k.endswith('.name') else k}={p.get(k)}" for k in differing
             if p.get(k) not in (None, "None")]
    return ", ".join(parts) or "all"


def compare_runs(run_ids: Sequence[str], overrides: Sequence[str]) -> CompareResult:
    """Compare finished runs: variants are the params that differ between them (seed excepted)."""
    from toolkit import plugins
    from toolkit.store.opening import open_store
    from toolkit.store.tracking import store_root

    store_path = None
    for o in overrides:
        if o.startswith("store="):
            store_path = o.split("=", 1)[1]
        else:
            raise JtError(f"unexpected argument '{o}' with --runs; only store=PATH is accepted")
    if len(run_ids) < 2:
        raise JtError("--runs needs at least two run ids")
    store = open_store(store_root(store_path))
    runs = [store.get_run(r) for r in run_ids]
    params = [r.data.params for r in runs]
    differing = differing_params(params)
    per_cell = [(variant_label(p, differing), r.info.run_id, dict(r.data.metrics)) for r, p in zip(runs, params)]
    task_name = params[0].get("task.name", "")
    keys: list[str] = []
    if task_name in plugins.names("task"):
        keys = list(getattr(plugins.load("task", task_name), "key_metrics", ()))
    exp = store.client.get_experiment(runs[0].info.experiment_id).name
    command = " ".join(["jt compare --runs", *run_ids, *overrides])
    run_id = store.start_run(exp, run_name=store.unique_run_name(exp, f"compare {len(runs)} runs"),
                             tags={**describe.provenance_tags(command), "jt.compare": "true"})
    store.log_params(run_id, {"runs": ",".join(run_ids), "differing": ",".join(differing) or "none"})
    out = _record(store, run_id, per_cell, keys, ", ".join(differing) or "runs", command)
    store.end_run(run_id, "FINISHED")
    return out


def _record(store: Any, run_id: str, per_cell: list[tuple[str, str, dict[str, float]]],
            keys: list[str], label: str, command: str) -> CompareResult:
    from toolkit.store import h5

    if not keys:  # every metric all runs share
        common = set.intersection(*(set(m) for _, _, m in per_cell)) if per_cell else set()
        keys = sorted(common)
    variants: dict[str, list[tuple[str, dict[str, float]]]] = {}
    for name, rid, m in per_cell:
        variants.setdefault(name, []).append((rid, m))
    rows = []
    for name, items in variants.items():
        row: dict[str, Any] = {"variant": name, "n": len(items), "runs": [rid for rid, _ in items]}
        for k in keys:
            vals = np.array([m.get(k, math.nan) for _, m in items], dtype=float)
            row[k] = (float(np.nanmean(vals)) if np.isfinite(vals).any() else math.nan,
                      float(np.nanstd(vals)) if np.isfinite(vals).any() else math.nan)
        rows.append(row)
    table = format_table(rows, keys)
    wd = store.workdir(run_id)
    (wd / "compare.txt").write_text(table + "\n")
    h5.write(wd / "compare.h5", {
        "variant": np.array([r["variant"] for r in rows], dtype="S"),
        "n": np.array([r["n"] for r in rows]),
        "mean": {k: np.array([r[k][0] for r in rows]) for k in keys},
        "std": {k: np.array([r[k][1] for r in rows]) for k in keys},
        "runs": {r["variant"].replace("/", "_"): np.array(r["runs"], dtype="S") for r in rows},
    }, attrs={"format": "jt.compare/1", "vary": label})
    _plot(rows, keys, wd / "compare.png", label)
    curves = _plot_curves(_curves(store, per_cell, keys), wd / "compare_curves.png", label)
    store.log_artifacts(run_id, wd)
    store.set_tags(run_id, {"jt.compare.runs": ",".join(rid for _, rid, _ in per_cell)[:5000]})
    labels: dict[str, str] = {}
    for r in rows:  # one metric per variant and statistic: <variant>/<metric>_mean, _std
        lab = metric_label(r["variant"])
        labels[r["variant"]] = lab if lab not in labels.values() else f"{lab}_{len(labels)}"
    with store.metrics(run_id) as buf:
        for r in rows:
            for k in keys:
                if not math.isnan(r[k][0]):
                    buf.add(f"{labels[r['variant']]}/{k}_mean", r[k][0])
                    buf.add(f"{labels[r['variant']]}/{k}_std", r[k][1])
            buf.add(f"{labels[r['variant']]}/n", float(r["n"]))
    names = {rid: store.get_run(rid).info.run_name for _, rid, _ in per_cell}
    note = "\n".join([
        f"**Comparison** of {label} ({len(per_cell)} runs): mean ± std over seeds.", "",
        # one row per metric, one column per variant: it stays a table in the UI's narrow
        # description pane (a row per variant wrapped every cell once there were 5+ metrics)
        describe.table(["metric", *(r["variant"] for r in rows)],
                       [[k, *(f"{r[k][0]:.4g} ± {r[k][1]:.2g}" for r in rows)] for k in keys]
                       + [["seeds (n)", *(r["n"] for r in rows)],
                          ["runs", *(", ".join(names.get(x) or x for x in r["runs"]) for r in rows)]]), "",
        f"Reproduce: `{command}`", "",
        "Metrics: `<variant>/<metric>_mean` and `_std`; the bar chart is the artifact `compare.png`, "
        "the numbers `compare.h5`; the compared runs are this run's children."
        + (f" `compare_curves.png`: {', '.join(curves)} against samples, mean over seeds (thick) and each seed."
           if curves else "")])
    store.set_tags(run_id, {describe.NOTE: describe.fit(note + "\n")})
    return CompareResult(table, run_id, store.root, rows)


def format_table(rows: list[dict[str, Any]], keys: list[str]) -> str:
    """Plain-text table: one row per variant, ``mean ± std`` per key metric."""
    head = ["variant", "n", *keys]
    body = [[r["variant"], str(r["n"]), *(f"{r[k][0]:.4g} ± {r[k][1]:.2g}" for k in keys)] for r in rows]
    widths = [max(len(x[i]) for x in [head, *body]) for i in range(len(head))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(line, widths)).rstrip() for line in [head, *body]]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def _plot(rows: list[dict[str, Any]], keys: list[str], path: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = max(1, len(keys))
    fig, axes = plt.subplots(1, n, figsize=(3.2 * n + 1, 3.2), squeeze=False)
    names = [r["variant"] for r in rows]
    for ax, k in zip(axes[0], keys):
        ax.bar(range(len(rows)), [r[k][0] for r in rows], yerr=[r[k][1] for r in rows], capsize=3)
        ax.set_xticks(range(len(rows)), names, rotation=30, ha="right", fontsize=7)
        ax.set_title(k, fontsize=9)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _curves(store: Any, per_cell: list[tuple[str, str, dict[str, float]]],
            keys: list[str]) -> dict[str, dict[str, list[np.ndarray]]]:
    """``{metric: {variant: [(n_points, 2) step/value per run]}}`` of each key metric a run logged
    as a curve (``train/<metric>``, at least two points: e.g. ``survival_s`` against samples)."""
    from toolkit.execution.runner import curve_key

    out: dict[str, dict[str, list[np.ndarray]]] = {}
    for name, rid, _ in per_cell:
        for k in keys:
            pts = sorted((int(m.step), float(m.value)) for m in store.client.get_metric_history(rid, curve_key(k)))
            if len(pts) > 1:
                out.setdefault(k, {}).setdefault(name, []).append(np.array(pts, dtype=float))
    return out


def _plot_curves(curves: dict[str, dict[str, list[np.ndarray]]], path: Path, title: str) -> list[str]:
    """``compare_curves.png``: per metric, each variant's runs (thin) and their mean at the steps
    they share (thick) against the step (samples); the metrics drawn (none: no file)."""
    if not curves:
        return []
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(curves), figsize=(4.2 * len(curves) + 1, 3.4), squeeze=False)
    for ax, (k, by_variant) in zip(axes[0], curves.items()):
        for i, (variant, runs) in enumerate(by_variant.items()):
            color = f"C{i % 10}"
            for r in runs:
                ax.plot(r[:, 0], r[:, 1], color=color, lw=0.7, alpha=0.5)
            steps = sorted(set.intersection(*(set(r[:, 0]) for r in runs)))
            if steps:
                mean = [np.mean([r[r[:, 0] == x, 1][0] for r in runs]) for x in steps]
                ax.plot(steps, mean, color=color, lw=2.0, label=f"{variant} (n={len(runs)})")
        ax.set_xlabel("samples")
        ax.set_title(k, fontsize=9)
        ax.legend(fontsize=7, loc="best")
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return list(curves)
