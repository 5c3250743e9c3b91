"""What a run says about itself in the MLflow UI: markdown descriptions and provenance tags.

MLflow shows a run's ``mlflow.note.content`` tag as the description on its Overview page (markdown),
an experiment's as the experiment's description, and ``mlflow.user`` / ``mlflow.source.git.commit``
as "Created by" and the source version. Every run jt makes gets them: outer runs (what ran, the
command that reproduces it, the headline metrics, where the pictures are), evaluations (their point
and seed, their metrics, their pictures) and comparisons (the table).
"""

from __future__ import annotations

import math
from typing import Any, Iterable, Mapping, Optional, Sequence

NOTE = "mlflow.note.content"
PICTURES = (".png", ".gif", ".mp4", ".jpg", ".svg")
LIMIT = 8000
"""Characters MLflow keeps of a tag value (it cuts longer ones, mid-row of a table)."""
MAX_ROWS = 40
"""Rows of a table in a description (the rest: in its file, and ``jt show``)."""


def fit(text: str, limit: int = LIMIT) -> str:
    """``text`` cut at a line boundary to at most ``limit`` characters, saying so."""
    if len(text) <= limit:
        return text
    tail = "\n\n… (cut to fit MLflow's 8000 characters; `jt show RUN_ID` prints everything)\n"
    return text[: text.rfind("\n", 0, limit - len(tail))] + tail


def provenance_tags(command: str) -> dict[str, str]:
    """MLflow's own source tags and jt's: user, git commit (without ``+dirty``), command, version."""
    from toolkit.execution import provenance
    from toolkit.store.tracking import user

    commit = provenance.git_commit()
    tags = {"mlflow.user": user(), "mlflow.source.name": "jt", "mlflow.source.type": "LOCAL",
            "jt.version": provenance.jt_version(), "jt.git_commit": commit, "jt.command": command}
    if commit != "unknown":
        tags["mlflow.source.git.commit"] = commit.split("+", 1)[0]
    return tags


def fmt(value: Any) -> str:
    """A number as a table shows it (4 significant digits), anything else as text."""
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, (int, float)):
        return "nan" if math.isnan(float(value)) else f"{float(value):.4g}"
    return str(value)


def table(header: Sequence[str], rows: Iterable[Sequence[Any]]) -> str:
    """A markdown table (``|`` in cells escaped)."""
    def cell(v: Any) -> str:
        return fmt(v).replace("|", "\\|").replace("\n", " ")

    rows = list(rows)
    lines = ["| " + " | ".join(cell(h) for h in header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in rows[:MAX_ROWS]]
    if len(rows) > MAX_ROWS:
        lines += ["", f"… {len(rows) - MAX_ROWS} more rows (all of them: `jt show RUN_ID`)"]
    return "\n".join(lines)


def headline(metrics: Mapping[str, float], keys: Sequence[str], limit: int = 8) -> list[tuple[str, float]]:
    """The metrics worth a first look: ``keys`` (and their ``best_``), then the others, at most ``limit``."""
    first = [k for key in keys for k in (key, f"best_{key}") if k in metrics]
    rest = [k for k in metrics if k not in first]
    return [(k, metrics[k]) for k in (first + rest)[:limit]]


def _pictures(names: Iterable[str]) -> list[str]:
    return sorted({n for n in names if n.lower().endswith(PICTURES)})


def outer(cfg: Any, command: str, metrics: Optional[Mapping[str, float]] = None, keys: Sequence[str] = (),
          pictures: Iterable[str] = (), nested: bool = True, summary: str = "") -> str:
    """The outer run's description: what ran, how to rerun it, headline metrics, where pictures are.

    Args:
        cfg: the run's composed config.
        command: the command that reproduces it.
        metrics: the run's final metrics (None while it runs).
        keys: the task's key metrics (shown first).
        pictures: artifact names of the run's own pictures.
        nested: whether evaluations are child runs.
        summary: extra markdown (e.g. the task's summary table).
    """
    t, s = cfg.task.name, cfg.search.name
    budget = cfg.search.get("budget", None)
    what = (f"task `{t}` searched by `{s}`" + (f" (budget {budget} evaluations)" if budget is not None else "")
            if nested else f"one evaluation of task `{t}`, in this run (search `{s}`)")
    lines = [f"**{t} · {s} · seed {cfg.seed}**: {what}.", ""]  # the UI shows ~3 lines before "Show more"
    if metrics is None:
        lines.append("Running; the headline metrics appear here when it finishes.")
    else:
        lines.append(table(["metric", "value"], headline(metrics, keys)))
    lines += ["", f"Reproduce: `{command}`"]
    pics = _pictures(pictures)
    where = []
    if pics:
        where.append("this run's artifacts: " + ", ".join(f"`{p}`" for p in pics))
    if nested:
        where.append("each evaluation's own pictures are in its child run `eval-NNNN` (expand this run in the list)")
    if where:
        lines += ["", "Pictures: " + "; ".join(where) + "."]
    if summary:
        lines += ["", summary]
    return fit("\n".join(lines).strip() + "\n")


def evaluation(index: int, parent: str, point: Mapping[str, float], seed: int, metrics: Mapping[str, float],
               keys: Sequence[str], artifacts: Iterable[str], failed: str = "") -> str:
    """An evaluation's description: its point (the take-off point, for a jump), seed, metrics, pictures."""
    where = ", ".join(f"`{k}={v:.4g}`" for k, v in point.items()) or "the task's defaults (no search parameters)"
    lines = [f"**Evaluation {index}** of `{parent}` at {where}, seed {seed}."]
    if failed:
        lines.append(f"Failed: {failed}.")
    lines += ["", table(["metric", "value"], headline(metrics, keys))]
    pics = _pictures(artifacts)
    if pics:
        lines += ["", "Pictures (artifacts): " + ", ".join(f"`{p}`" for p in pics) + "."]
    return fit("\n".join(lines) + "\n")


def ensure_experiment(store: Any, task: str, task_cls: Any) -> str:
    """Experiment ``task`` (created if missing) with its description and tags; its id.

    ``mlflow.experimentKind = custom_model_development`` files it as model training (not GenAI),
    and jt's saved view shows the task's key metrics as the runs table's columns
    (``toolkit.store.ui.experiment_tags``; ``jt ui`` opens it).
    """
    from toolkit.store.ui import experiment_tags

    summary = ((getattr(task_cls, "__doc__", None) or "").strip().splitlines() or [""])[0]
    return store.describe_experiment(task, experiment(task, summary), {
        "jt.task": task, **experiment_tags(tuple(getattr(task_cls, "key_metrics", ())))})


def experiment(task: str, summary: str) -> str:
    """An experiment's description (one experiment per task)."""
    return (f"Runs of the jt task `{task}`" + (f": {summary}" if summary else ".") + "\n\n"
            f"Outer runs are named `{task}·<search>·seed<N>`; a searcher's evaluations are their child "
            "runs `eval-NNNN`; a `jt compare` is a run `compare ...` whose children are the compared runs "
            "(`<variant>·seed=<N>`). Each run's description says what it is and how to rerun it.\n")
