"""``jt show RUN_ID``: a run's status, description, config, metrics, summary table and artifacts
as text; ``jt show RUN_ID --artifact NAME`` one artifact (an HDF5 file as its preview)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Optional

from toolkit.errors import JtError

TEXT = (".txt", ".md", ".yaml", ".yml", ".json", ".csv", ".tsv", ".log")
IMAGES = (".png", ".gif", ".jpg", ".jpeg")


def show(run_id: str, store_path: Optional[str] = None, artifact: Optional[str] = None) -> str:
    """Text description of run ``run_id`` in the store (or of its artifact ``artifact``)."""
    from toolkit.store.tracking import store_root
    from toolkit.store.opening import open_store

    store = open_store(store_root(store_path), must_exist=True)  # reading never creates a store
    run = store.get_run(run_id)
    art = store.artifact_dir(run_id)
    if artifact is not None:
        return show_artifact(art, artifact, run_id)
    exp = store.client.get_experiment(run.info.experiment_id)
    lines = [f"run {run_id}  [{run.info.status}]  experiment '{exp.name}'  name '{run.info.run_name}'"]
    tags = {k: v for k, v in run.data.tags.items() if k.startswith("jt.") or k == "mlflow.parentRunId"}
    for k in sorted(tags):
        lines.append(f"  {k}: {tags[k]}")
    note = run.data.tags.get("mlflow.note.content", "").strip()
    if note:
        lines.append("description:")
        lines.extend("  " + ln for ln in note.splitlines())
    cfg = art / "config.yaml"
    lines.append("config:")
    if cfg.is_file():
        lines.extend("  " + ln for ln in cfg.read_text().rstrip().splitlines())
    else:
        lines.extend(f"  {k}: {v}" for k, v in sorted(run.data.params.items()))
    lines.append("metrics:")
    lines.extend(f"  {k}: {v:.6g}" for k, v in sorted(run.data.metrics.items()))
    table = art / "summary_table.json"
    if table.is_file():
        got = json.loads(table.read_text())
        lines.append("summary table:")
        lines.extend("  " + ln for ln in text_table(got["header"], got["rows"]).splitlines())
    lines.append(f"artifacts ({art}; one of them: jt show {run_id} --artifact NAME):")
    if art.is_dir():
        for p in sorted(art.rglob("*")):
            if p.is_file():
                lines.append(f"  {p.relative_to(art)}  ({p.stat().st_size} bytes)")
    children = store.client.search_runs([run.info.experiment_id],
                                        filter_string=f"tags.mlflow.parentRunId = '{run_id}'")
    if children:
        lines.append(f"child runs: {len(children)}")
        for c in sorted(children, key=lambda r: r.info.run_name or ""):
            lines.append(f"  {c.info.run_id}  {c.info.run_name}  [{c.info.status}]")
    return "\n".join(lines)


def text_table(header: list[str], rows: list[list[Any]]) -> str:
    """Plain-text columns, numbers with 4 significant digits."""
    from toolkit.execution.describe import fmt

    body = [[fmt(v) for v in row] for row in rows]
    widths = [max(len(x[i]) for x in [header, *body]) for i in range(len(header))]
    out = ["  ".join(c.ljust(w) for c, w in zip(line, widths)).rstrip() for line in [header, *body]]
    out.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(out)


def show_artifact(art: Path, name: str, run_id: str = "") -> str:
    """One artifact as text: an HDF5 file's preview, a text file's contents, an image's size.

    Raises:
        JtError: no such artifact (the line lists the run's artifacts).
    """
    path = (art / name).resolve()
    if not str(path).startswith(str(art.resolve())) or not path.is_file():
        names = sorted(str(p.relative_to(art)) for p in art.rglob("*") if p.is_file()) if art.is_dir() else []
        raise JtError(f"run {run_id} has no artifact '{name}'; it has: {', '.join(names) or 'none'}")
    suffix = path.suffix.lower()
    if suffix == ".h5":
        from toolkit.store import h5

        return h5.preview(path).rstrip("\n")
    if suffix in TEXT:
        return path.read_text(errors="replace").rstrip("\n")
    if suffix in IMAGES:
        from PIL import Image

        with Image.open(path) as im:
            frames = getattr(im, "n_frames", 1)
            return (f"{name}: {im.format} image, {im.width} × {im.height} px"
                    + (f", {frames} frames" if frames > 1 else "") + f", {path.stat().st_size} bytes "
                    "(open it in jt ui, or from the artifacts folder above)")
    return f"{name}: {path.stat().st_size} bytes (binary; not shown)"
