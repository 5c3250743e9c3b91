"""Stage 2, novel policy seeking (``000`` §5.2, eqs 12 and 15; thesis ``001`` §3.5.2).

``jt run task=highjump task.stage=2 task.init=RUN_ID`` trains ONE new policy (``search=single``)
from the take-off state of a Stage-1 evaluation, warm-started from that evaluation's policy
(``000`` §7.1.1: "Training is warm started with the associated Stage 1 policy"), with the reward
``r_task · r_naturalness · r_novelty`` (``conf/reward/highjump_stage2.yaml``). The novelty term
(eq 12, ``d_threshold = π/2``, rotation-angle distance) compares each episode's root orientation at
the bar plane (``000`` §6.1.4, quaternion x,y,z,w in the suite frame, ``w >= 0``) with the set Π of
policies found so far.

``task.init`` names (``resolve``):

* a nested evaluation run of a Stage-1 search: that evaluation;
* an outer Stage-1 run: its evaluation ``task.init_eval`` (``jt.eval_index``), or, with
  ``init_eval = -1``, the best one: not failed first, then ``final_success``, ``bar_height_reached``,
  ``mean_return`` (higher is better), then the lower index;
* a run of ``search=single`` (the evaluation is logged on the run itself);
* a folder holding ``ppo.h5`` and ``rollout.h5`` (or the ``ppo.h5`` itself).

From it: the take-off state (the evaluation's ``takeoff_*`` metrics, else its params) and the
policy ``ppo.h5`` artifact. Π = the evaluation's own feature (``feature_q0..3``, if its jump crossed
the plane) + the features of the FINISHED Stage-2 runs in the store whose ``task.init`` resolves to
the same evaluation (found through their logged params ``task.stage``, ``task.init``,
``task.init_eval``) + ``task.policy_features``. Running the command again therefore adds one policy
per run, as the paper's "five DRL iterations from each good initial state" (``000`` §7.1.1).

Warm start (``Stage2Init.checkpoint``, trained with ``toolkit.rl.ppo.train(..., warm_start=)`` on
a config built by ``toolkit.rl.with_architecture``): the Stage-2 run is a fresh PPO run (FRESH
optimisers, counters at 0, the seeded RNGs of a fresh run) whose policy, value network and
observation normaliser (with its running statistics) and network sizes are the Stage-1
checkpoint's; a killed Stage-2 evaluation resumes from its own ``ppo.h5``. The curriculum starts
afresh (the paper does not say; ours).
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path
from typing import Any, Optional

_WARNED: set = set()  # sources already warned about in this process
FEATURE_KEYS = tuple(f"feature_q{i}" for i in range(4))  #: metrics holding the Stage-2 feature


@dataclasses.dataclass
class Stage2Init:
    """What ``task.init`` resolved to.

    Attributes:
        source: canonical name of the evaluation (its run id, or the resolved folder).
        run_id: the run holding the policy (``""`` for a folder).
        eval_index: its ``jt.eval_index`` (-1 when not a nested evaluation).
        checkpoint: the Stage-1 ``ppo.h5``.
        features: take-off state ``{name: value}``.
        policy_features: Π, ``(n, 4)`` as lists (x, y, z, w).
        previous_runs: ids of the earlier Stage-2 runs whose features are in Π.
    """

    source: str
    run_id: str
    eval_index: int
    checkpoint: Path
    features: dict
    policy_features: list
    previous_runs: list


def _err(msg: str) -> Exception:
    from toolkit.errors import JtError

    return JtError(msg)


def _feature(metrics: dict) -> Optional[list]:
    """``feature_q0..3`` of a run's metrics, None when absent (the jump never crossed the plane)."""
    if not all(k in metrics and math.isfinite(float(metrics[k])) for k in FEATURE_KEYS):
        return None
    return [float(metrics[k]) for k in FEATURE_KEYS]


def _rank(run: Any) -> tuple:
    """How good a Stage-1 evaluation is (larger is better; ``resolve`` breaks ties by lower index)."""
    m = run.data.metrics
    return (m.get("failed", 1.0) == 0.0, m.get("final_success", 0.0), m.get("bar_height_reached", 0.0),
            m.get("mean_return", 0.0))


def _source(store: Any, init: str, init_eval: int) -> tuple[Any, str]:
    """``(Resolved, canonical source)`` of ``task.init`` / ``task.init_eval`` (``toolkit.store.resolve``).

    ``store`` is the store's path or an open ``Store``; the source is the evaluation's run id, or
    the folder holding the ``ppo.h5``.
    """
    from toolkit.store.resolve import resolve as find

    got = find(init, artifact="ppo.h5", store=store, best_by=_rank, eval_index=init_eval, what="task.init",
               label="trained policy", hint="give a Stage-1 jumping run or evaluation", index_what="task.init_eval")
    return got, got.run_id if got.run is not None else str(got.folder)


def _previous_stage2(store: Any, experiment: str, source: str) -> list[tuple[str, list]]:
    """``(run id, feature)`` of the FINISHED Stage-2 runs of ``experiment`` started from ``source``.

    ``store`` is an open ``Store`` or None (no store yet: no earlier runs).
    """
    from toolkit.store.resolve import search_runs

    exp = store.client.get_experiment_by_name(experiment) if store is not None else None
    if exp is None:
        return []
    runs = search_runs(store, [exp.experiment_id], params={"task.stage": "2"}, status="FINISHED")
    out = []
    for r in sorted(runs, key=lambda r: r.info.start_time):
        init = r.data.params.get("task.init", "")
        try:
            _, src = _source(store, init, int(r.data.params.get("task.init_eval", -1)))
        except Exception:  # noqa: BLE001 - its init is gone or unreadable: not ours
            continue
        f = _feature(r.data.metrics)
        if src == source and f is not None:
            out.append((r.info.run_id, f))
    return out


def resolve(params: Any, store_path: str, experiment: str, feature_names: tuple) -> Stage2Init:
    """Resolve ``task.init`` (see the module docstring); every problem is a one-line ``JtError``.

    Args:
        params: the task's ``JumpConfig`` (``stage``, ``init``, ``init_eval``, ``policy_features``).
        store_path: the run's ``store``.
        experiment: the experiment the Stage-2 runs are logged in (the task name).
        feature_names: take-off features of the task.
    """
    from toolkit.store import h5
    from toolkit.store.resolve import open_store

    init = str(params.init or "").strip()
    if not init:
        raise _err("task.stage=2 needs task.init=<RUN_ID of a Stage-1 run or evaluation> (000 §5.2)")
    store = open_store(store_path)  # None: no store yet (a folder init); never created here
    got, source = _source(store if store is not None else store_path, init, int(params.init_eval))
    own: Optional[list] = None
    if got.run is None:  # a folder, or a file in it
        folder = got.folder
        ckpt, ro = folder / "ppo.h5", folder / "rollout.h5"
        if not ckpt.is_file() or not ro.is_file():
            raise _err(f"task.init={init}: needs ppo.h5 and rollout.h5 in {folder}")
        import ast

        data, attrs = h5.read(ro), h5.read_attrs(ro)
        raw = attrs.get("features", "{}")
        feats = {k: float(v) for k, v in (ast.literal_eval(raw) if isinstance(raw, str) else {}).items()}
        q = [float(x) for x in data.get("feature_quat", [])]
        own = q if len(q) == 4 and all(math.isfinite(x) for x in q) else None
        run_id, index = "", -1
    else:
        ev = got.run
        run_id, m = got.run_id, ev.data.metrics
        if ev.data.params.get("task.stage", "1") == "2":
            raise _err(f"task.init={init} is a Stage-2 run; start from its Stage-1 init "
                       f"{ev.data.params.get('task.init', '?')}")
        ckpt = got.path
        feats = {k: float(m[f"takeoff_{k}"]) for k in feature_names if f"takeoff_{k}" in m}
        for k in feature_names:  # nested evaluations also carry their point as params
            if k not in feats and k in ev.data.params:
                feats[k] = float(ev.data.params[k])
        own = _feature(m)
        index = got.eval_index
    missing = [k for k in feature_names if k not in feats]
    if missing:
        raise _err(f"task.init={init}: no take-off {', '.join(missing)} recorded (not a {experiment} run?)")
    prev = _previous_stage2(store, experiment, source)
    pi = ([own] if own is not None else []) + [f for _, f in prev]
    pi += [[float(x) for x in f] for f in (params.policy_features or [])]
    if own is None and source not in _WARNED:
        _WARNED.add(source)
        print(f"jt: stage 2: the init policy's jump never crossed the bar plane (no feature); "
              f"Π has {len(pi)} feature(s)", file=sys.stderr, flush=True)
    return Stage2Init(source=source, run_id=run_id, eval_index=index, checkpoint=ckpt,
                      features={k: feats[k] for k in feature_names}, policy_features=pi,
                      previous_runs=[r for r, _ in prev])


def check_reward(terms: dict, task: str = "highjump") -> None:
    """Stage 2 needs the ``novelty`` term (eq 15); one-line error otherwise."""
    if "novelty" not in (terms or {}):
        raise _err(f"task.stage=2: the reward has no 'novelty' term (000 eq 15); add reward={task}_stage2")


# ---------------------------------------------------------------------------- metrics
def novelty_metrics(feature: Any, policy_features: list, terms: dict) -> dict[str, float]:
    """Novelty of the final deterministic jump vs Π with the reward's own ``novelty`` term.

    Returns ``novelty`` (eq 12's value) and ``novelty_distance`` (rad, min over Π) when the jump
    crossed the plane and Π is not empty (an empty Π gives novelty 1, no distance), and always
    ``novelty_set_size`` = |Π|.
    """
    import numpy as np

    from toolkit import plugins

    out = {"novelty_set_size": float(len(policy_features))}
    f = np.asarray(feature, dtype=float).reshape(-1)
    if f.size != 4 or not np.all(np.isfinite(f)):
        return out
    term = plugins.load("reward", "novelty")(terms["novelty"])
    pi = np.asarray(policy_features, dtype=float).reshape(-1, 4)
    out["novelty"] = float(term({"feature": f, "policy_features": pi}))
    if len(pi):
        out["novelty_distance"] = float(term.min_distance(f, pi))
    return out
