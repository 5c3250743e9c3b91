"""``action.prior=auto``: the store's own pose prior, trained on first use from the shipped clips.

A P-VAE / C-VAE action space needs a trained prior (``000`` §4.2, ``003`` §3.5). With
``action.prior=auto`` (the default), ``jt run`` looks in the run's store for the prior it trained
earlier with the default settings (tag ``jt.auto_prior``), and trains one if there is none:
``jt run task=pose_prior action=<kind>`` in the same store, about a minute on 2 cores (a run with
``experiment=smoke`` gets its own smoke-sized prior, ``experiment=smoke`` of ``task=pose_prior``). The run's
saved config then names that prior run, so a resumed or repeated run uses the same prior.
"""

from __future__ import annotations

import sys
from typing import Any, Sequence

AUTO = "auto"
"""The ``action.prior`` value that asks for the store's own prior."""
KINDS = ("pvae", "cvae")
TAG = "jt.auto_prior"
"""Tag on a pose_prior run trained for ``action.prior=auto`` (its value: the prior kind)."""


def wants_auto(cfg: Any) -> str:
    """The prior kind (``"pvae"`` / ``"cvae"``) when ``cfg`` asks for ``action.prior=auto``, else ``""``."""
    action = cfg.get("action") if hasattr(cfg, "get") else None
    if action is None or str(cfg.task.name) == "pose_prior":
        return ""
    kind = str(action.get("name", ""))
    if kind in KINDS and str(action.get("prior", "")).strip() == AUTO:
        return kind
    return ""


def find(store: Any, tag: str) -> str:
    """Id of the newest finished auto prior run tagged ``tag`` (``pvae``, ``cvae``, ``pvae@smoke``
    ...) in ``store`` whose ``prior.h5`` is there, or ``""``."""
    kind = tag.split("@")[0]
    exp = store.client.get_experiment_by_name("pose_prior")
    if exp is None:
        return ""
    runs = store.client.search_runs(
        [exp.experiment_id], filter_string=f"tags.`{TAG}` = '{tag}' and attributes.status = 'FINISHED'",
        order_by=["attributes.start_time DESC"], max_results=20)
    from toolkit.priors.io import load_prior

    for r in runs:
        try:
            load_prior(r.info.run_id, str(store.root), kind=kind)
        except Exception:  # noqa: BLE001 - a broken or deleted prior is skipped, not fatal
            continue
        return r.info.run_id
    return ""


def resolve(cfg: Any, train_overrides: Sequence[str] = ()) -> Any:
    """``cfg`` with ``action.prior=auto`` replaced by a prior run id of this store (trained if needed).

    Args:
        cfg: a composed, validated config; returned unchanged unless it asks for ``auto``.
        train_overrides: extra overrides of the prior's own run (tests: ``experiment=smoke``).
    """
    kind = wants_auto(cfg)
    if not kind:
        return cfg
    from toolkit.store.tracking import Store, store_root

    store = Store(store_root(str(cfg.store)))
    smoke = str(cfg.get("profile", "default")) == "smoke"  # a smoke run gets a smoke-sized prior
    tag = f"{kind}@smoke" if smoke else kind
    run_id = find(store, tag)
    if run_id:
        print(f"jt: action.prior=auto: the store's {kind} prior, run {run_id}", file=sys.stderr, flush=True)
    else:
        run_id = train(store, kind, [*(["experiment=smoke"] if smoke else []), *train_overrides], tag)
    cfg.action.prior = run_id
    return cfg


def train(store: Any, kind: str, overrides: Sequence[str] = (), tag: str = "") -> str:
    """Train the default ``kind`` prior into ``store`` (``jt run task=pose_prior action=<kind>``); its run id."""
    from toolkit.config import compose
    from toolkit.execution.runner import run

    print(f"jt: action.prior=auto: no {kind} prior in this store yet; training one from the shipped "
          f"clips first (about a minute; later runs reuse it): jt run task=pose_prior action={kind}",
          file=sys.stderr, flush=True)
    conf = compose(["task=pose_prior", f"action={kind}", f"store={store.root}", *overrides])
    res = run(conf)
    store.set_tags(res.run_id, {TAG: tag or kind})
    return res.run_id
