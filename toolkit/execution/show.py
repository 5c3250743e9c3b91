"""``jt show RUN_ID``: a run's status, config, final metrics and artifacts as text."""

from __future__ import annotations

from typing import Optional


def show(run_id: str, store_path: Optional[str] = None) -> str:
    """Text description of run ``run_id`` in the store."""
    from toolkit.store.tracking import Store, store_root

    store = Store(store_root(store_path))
    run = store.get_run(run_id)
    exp = store.client.get_experiment(run.info.experiment_id)
    lines = [f"run {run_id}  [{run.info.status}]  experiment '{exp.name}'  name '{run.info.run_name}'"]
    tags = {k: v for k, v in run.data.tags.items() if k.startswith("jt.") or k == "mlflow.parentRunId"}
    for k in sorted(tags):
        lines.append(f"  {k}: {tags[k]}")
    art = store.artifact_dir(run_id)
    cfg = art / "config.yaml"
    lines.append("config:")
    if cfg.is_file():
        lines.extend("  " + ln for ln in cfg.read_text().rstrip().splitlines())
    else:
        lines.extend(f"  {k}: {v}" for k, v in sorted(run.data.params.items()))
    lines.append("metrics:")
    lines.extend(f"  {k}: {v:.6g}" for k, v in sorted(run.data.metrics.items()))
    lines.append(f"artifacts ({art}):")
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
