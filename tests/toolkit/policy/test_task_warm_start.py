"""``task.warm_start=RUN``: training that starts from a trained run's networks (the policy layer)."""

from __future__ import annotations

import numpy as np
import pytest

from toolkit.errors import JtError


def _run(tmp_path, *extra):
    from toolkit.config import compose
    from toolkit.execution.runner import run

    return run(compose(["task=runup", "experiment=smoke", f"store={tmp_path}", *extra]))


def _policy(res):
    from toolkit.rl.checkpoint import load

    path = res.store.artifact_dir(res.run_id)
    found = sorted(path.rglob("ppo.h5"))
    assert found, path
    groups, attrs = load(found[0])
    return groups, attrs, found[0]


def test_a_warm_started_run_starts_from_the_trained_networks(tmp_path):
    trained = _run(tmp_path)
    g0, _, src = _policy(trained)
    warm = _run(tmp_path, f"task.warm_start={trained.run_id}")
    fresh = _run(tmp_path, "seed=1")
    g1, a1, _ = _policy(warm)
    g2, _, _ = _policy(fresh)
    assert a1["warm_start"] == str(src)  # provenance: the checkpoint it started from
    assert int(g1["counters"]["samples"]) == int(g0["counters"]["samples"])  # a fresh budget, not a resume
    # the normaliser went on from the trained run's statistics: its count holds both runs' samples
    n0, n1 = (float(np.asarray(g["obs_norm"]["count"])) for g in (g0, g1))
    assert n1 > n0 and float(np.asarray(g2["obs_norm"]["count"])) < n1
    w0, w1, w2 = (np.concatenate([np.ravel(np.asarray(v)) for _, v in sorted(g["policy"].items())])
                  for g in (g0, g1, g2))
    # a few updates away from where it started; a fresh start is far from it
    assert np.linalg.norm(w1 - w0) < np.linalg.norm(w2 - w0)


@pytest.mark.parametrize("value, message", [
    ("nope", r"task.warm_start=nope: .*train one with: jt run task=runup"),
])
def test_a_missing_warm_start_is_one_line_before_a_run_opens(tmp_path, value, message):
    from toolkit.config import compose

    with pytest.raises(JtError, match=message):
        compose(["task=runup", "experiment=smoke", f"store={tmp_path}", f"task.warm_start={value}"])
    assert not (tmp_path / "mlflow.db").exists()


def test_warm_start_with_evaluate_or_of_another_task_is_one_line(tmp_path):
    from toolkit.config import compose

    trained = _run(tmp_path)
    with pytest.raises(JtError, match=r"task.warm_start=\w+: task.evaluate measures a trained policy without "
                                      r"training; give one of the two"):
        compose(["task=runup", "experiment=smoke", f"store={tmp_path}", f"task.warm_start={trained.run_id}",
                 f"task.evaluate={trained.run_id}"])
    with pytest.raises(JtError, match=r"task.warm_start=\w+: its policy takes 125 observations and gives 28 actions; "
                                      r"task=spacetime as configured here observes 148"):
        compose(["task=spacetime", "experiment=smoke", "action=raw", f"store={tmp_path}",
                 f"task.warm_start={trained.run_id}"])


def test_a_slim_policy_cannot_warm_start(tmp_path):
    from toolkit.config import compose
    from toolkit.rl.checkpoint import slim

    trained = _run(tmp_path)
    _, _, src = _policy(trained)
    slim(src, tmp_path / "slim.h5")
    with pytest.raises(JtError, match=r"is a slim policy \(a shipped skill's: no value network\)"):
        compose(["task=runup", "experiment=smoke", f"store={tmp_path}", f"task.warm_start={tmp_path / 'slim.h5'}"])
