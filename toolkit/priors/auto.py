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
from typing import Any, Callable, Sequence

AUTO = "auto"
"""The ``action.prior`` value that asks for the store's own prior."""
TAG = "jt.auto_prior"
"""Tag on a prior run trained for ``action.prior=auto`` (its value: the action space's name)."""


def prior_run(cfg: Any) -> list[str]:
    """The overrides of the run that trains ``cfg``'s action-space prior when ``cfg`` asks for
    ``action.prior=auto`` (the action space's ``ActionSpace.prior_run`` hook), else ``[]``; also
    ``[]`` for that training run itself (its task is the one the overrides name)."""
    from toolkit import plugins

    action = cfg.get("action") if hasattr(cfg, "get") else None
    if action is None or "name" not in action:
        return []
    hook = getattr(plugins.load("action", str(action.name)), "prior_run", None)
    overrides = list(hook(action) or []) if hook is not None else []
    if f"task={cfg.task.name}" in overrides:
        return []
    return overrides


def wants_auto(cfg: Any) -> str:
    """The action space's name when ``cfg`` asks for ``action.prior=auto``, else ``""``."""
    return str(cfg.action.name) if prior_run(cfg) else ""


def find(store: Any, tag: str, experiment: str) -> str:
    """Id of the newest finished auto prior run tagged ``tag`` (``pvae``, ``cvae``, ``pvae@smoke``
    ...) in ``store``'s ``experiment`` whose prior still loads, or ``""``."""
    kind = tag.split("@")[0]
    exp = store.client.get_experiment_by_name(experiment)
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


def resolve(cfg: Any, train: Callable[[Any, Sequence[str], str], str], train_overrides: Sequence[str] = ()) -> Any:
    """``cfg`` with ``action.prior=auto`` replaced by a prior run id of this store (trained if needed).

    Args:
        cfg: a composed, validated config; returned unchanged unless it asks for ``auto``.
        train: ``train(store, overrides, tag) -> run id``: runs the prior's training (the runner
            passes its own ``run``, so this module never calls it back).
        train_overrides: extra overrides of the prior's own run (tests: ``experiment=smoke``).
    """
    overrides = prior_run(cfg)
    if not overrides:
        return cfg
    from toolkit.store.tracking import store_root
    from toolkit.store.opening import open_store

    kind = str(cfg.action.name)
    experiment = next(o.partition("=")[2] for o in overrides if o.startswith("task="))
    store = open_store(store_root(str(cfg.store)))
    smoke = str(cfg.get("profile", "default")) == "smoke"  # a smoke run gets a smoke-sized prior
    tag = f"{kind}@smoke" if smoke else kind
    run_id = find(store, tag, experiment)
    if run_id:
        print(f"jt: action.prior=auto: the store's {kind} prior, run {run_id}", file=sys.stderr, flush=True)
    else:
        print(f"jt: action.prior=auto: no {kind} prior in this store yet; training one from the shipped "
              f"clips first (about a minute; later runs reuse it): jt run {' '.join(overrides)}",
              file=sys.stderr, flush=True)
        run_id = train(store, [*overrides, *(["experiment=smoke"] if smoke else []), *train_overrides], tag)
        store.set_tags(run_id, {TAG: tag})
    cfg.action.prior = run_id
    return cfg
