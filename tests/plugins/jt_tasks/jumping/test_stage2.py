"""Stage 2 (000 §5.2): a real tiny Stage-1 run in a temp store, then Stage-2 runs from it.

Covers: resolving ``task.init`` (outer run → best evaluation, nested evaluation, ``init_eval``),
the warm start (the Stage-2 checkpoint before training IS the Stage-1 policy), the novelty set Π
(the init's feature, earlier Stage-2 runs of the same init, ``task.policy_features``), the
novelty metrics, and the one-line errors.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

SMOKE = ["task=highjump", "experiment=smoke", "agent.total_samples=64"]


def _compose(store, *extra):
    from toolkit.config import compose

    stage2 = ["reward=highjump_stage2"] if "task.stage=2" in extra and not any(e.startswith("reward=") for e in extra) else []
    return compose([*SMOKE, f"store={store}", *stage2, *extra])


@pytest.fixture(scope="module")
def stage1(tmp_path_factory):
    """``(store root, outer run id, evaluation run id, Store)`` of a 1-evaluation BDS run."""
    from toolkit.execution.runner import run

    root = tmp_path_factory.mktemp("store")
    res = run(_compose(root, "search=bds", "search.budget=1"))
    kids = res.store.client.search_runs([res.store.experiment_id("highjump")],
                                        filter_string=f"tags.mlflow.parentRunId = '{res.run_id}'")
    assert len(kids) == 1
    return root, res.run_id, kids[0].info.run_id, res.store


def _h5(path):
    from toolkit.rl.checkpoint import load

    return load(path)[0]


def _same_tree(a, b):
    assert set(a) == set(b)
    for k in a:
        np.testing.assert_array_equal(np.asarray(a[k]), np.asarray(b[k]))


def test_warm_start_takes_the_stage1_policy_state_and_features(stage1):
    from toolkit.execution.runner import run

    root, outer, ev_id, store = stage1
    # zero training samples: the Stage-2 policy is exactly its warm start
    res = run(_compose(root, "task.stage=2", f"task.init={outer}", "agent.total_samples=0",
                       "task.policy_features=[[0.0,0.0,0.0,1.0]]"))
    s1, s2 = _h5(store.artifact_dir(ev_id) / "ppo.h5"), _h5(store.artifact_dir(res.run_id) / "ppo.h5")
    _same_tree(s1["policy"], s2["policy"])
    _same_tree(s1["value"], s2["value"])
    _same_tree(s1["obs_norm"], s2["obs_norm"])  # normaliser incl. running statistics
    assert s2["counters"] == {"iteration": 0, "samples": 0}
    assert s2["policy_optim"]["state"] == {}  # a fresh optimiser
    run2 = store.get_run(res.run_id)
    m1, m2 = store.get_run(ev_id).data.metrics, run2.data.metrics
    for k in ("alpha", "omega_x", "omega_z", "v_z"):  # the Stage-1 take-off state
        assert m2[f"takeoff_{k}"] == pytest.approx(m1[f"takeoff_{k}"])
    own = 1 if "feature_q0" in m1 else 0  # the init's feature is in Π when its jump crossed the bar
    assert m2["novelty_set_size"] == 1 + own and m2["init_eval_index"] == 0
    assert run2.info.status == "FINISHED"
    for name in ("ppo.h5", "rollout.h5", "filmstrip.png"):
        assert (store.artifact_dir(res.run_id) / name).is_file(), name


def test_stage2_trains_with_the_novelty_reward(stage1):
    from toolkit.execution.runner import run

    root, _, ev_id, store = stage1
    res = run(_compose(root, "task.stage=2", f"task.init={ev_id}", "task.policy_features=[[0.0,0.0,0.0,1.0]]"))
    m = store.get_run(res.run_id).data.metrics
    assert m["samples"] == 64 and m["novelty_set_size"] >= 1
    assert math.isfinite(m["mean_return"])  # an uncrossed episode no longer makes the reward NaN
    nov = store.client.get_metric_history(res.run_id, "train/novelty")  # per-iteration mean r_novelty
    assert nov and all(0.01 <= h.value <= 1.0 for h in nov)
    if "feature_q0" in m:  # the final jump crossed: its novelty vs Π is a metric
        assert 0.01 <= m["novelty"] <= 1.0
    assert _h5(store.artifact_dir(res.run_id) / "ppo.h5")["counters"]["samples"] == 64


def test_pi_collects_earlier_stage2_runs_of_the_same_evaluation(stage1):
    """Earlier FINISHED Stage-2 runs whose init resolves to the same evaluation join Π."""
    from toolkit import plugins

    root, outer, ev_id, store = stage1
    q_prev = [0.0, 0.0, math.sin(0.5), math.cos(0.5)]
    for init, q in ((outer, q_prev), ("0123456789abcdef0123456789abcdef", [1.0, 0.0, 0.0, 0.0])):
        rid = store.start_run("highjump", tags={"test": "fake stage2"})
        store.log_params(rid, {"task.stage": 2, "task.init": init, "task.init_eval": -1})
        with store.metrics(rid) as buf:
            buf.add_many({f"feature_q{i}": v for i, v in enumerate(q)})
        store.end_run(rid)
    task = plugins.load("task", "highjump")(_compose(root, "task.stage=2", f"task.init={ev_id}",
                                                     "task.policy_features=[[0.0,0.0,0.0,1.0]]"))
    init = task.stage2_init()
    assert init.run_id == ev_id and init.source == ev_id and init.checkpoint.name == "ppo.h5"
    assert q_prev in init.policy_features and [1.0, 0.0, 0.0, 0.0] not in init.policy_features
    assert [0.0, 0.0, 0.0, 1.0] in init.policy_features
    assert task.problem().space.names == []  # the take-off state is fixed: one evaluation
    spec = task.env_spec({})
    assert spec.policy_features == init.policy_features and "novelty" in spec.reward_terms
    from jt_tasks.jumping.stage2 import novelty_metrics

    out = novelty_metrics([0.0, 0.0, 0.0, 1.0], init.policy_features, spec.reward_terms)
    assert out["novelty"] == pytest.approx(0.01) and out["novelty_distance"] == pytest.approx(0.0, abs=1e-6)
    far = novelty_metrics([1.0, 0.0, 0.0, 0.0], [[0.0, 0.0, 0.0, 1.0]], spec.reward_terms)
    assert far["novelty"] == 1.0 and far["novelty_distance"] == pytest.approx(math.pi)  # eq 12 clip at 1


@pytest.mark.parametrize("extra, match", [
    (["task.stage=2"], "needs task.init"),
    (["task.stage=2", "task.init=0123456789abcdef0123456789abcdef"], "no such run"),
    (["task.stage=2", "task.init=OUTER", "task.init_eval=5"], "init_eval=5"),
    (["task.stage=2", "task.init=EMPTY"], "no trained policy"),
    (["task.init=OUTER"], "add task.stage=2"),
    (["task.stage=2", "task.init=OUTER", "search=bds"], "search=single"),
    (["task.stage=2", "task.init=OUTER", "reward=highjump"], "add reward=highjump_stage2"),
])
def test_bad_init_is_one_line(stage1, extra, match):
    from toolkit.errors import JtError
    from toolkit.execution.runner import run

    root, outer, _, store = stage1
    empty = store.start_run("highjump")
    store.end_run(empty)
    extra = [e.replace("OUTER", outer).replace("EMPTY", empty) for e in extra]
    with pytest.raises(JtError, match=match) as err:
        run(_compose(root, *extra))
    assert "\n" not in str(err.value)
