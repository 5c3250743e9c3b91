"""The task end to end: search problem, a tiny evaluation, its artifacts, resuming from ppo.h5."""

from __future__ import annotations

import math

import numpy as np
import pytest


def _cfg(*extra):
    from toolkit.config import compose

    return compose(["task=highjump", "search=bds", "experiment=smoke", *extra])


def test_problem_is_the_take_off_box_with_an_angle_feature():
    from toolkit import plugins

    task = plugins.load("task", "highjump")(_cfg())
    pr = task.problem()
    assert pr.space.names == ["alpha", "omega_x", "omega_z", "v_z"]
    assert pr.space.defaults() == [-0.05, -3.0, 1.0, -2.40]  # Fosbury flop, 000 Table 3
    assert pr.n_features == 1 and list(pr.feature_low) == [0.0] and list(pr.feature_high) == [math.pi]


def test_tiny_evaluation_writes_artifacts_and_resumes(tmp_path):
    from toolkit import plugins
    from toolkit.interfaces.task import EvalContext
    from toolkit.rl.checkpoint import load

    task = plugins.load("task", "highjump")(_cfg())
    ctx = EvalContext(index=0, seed=7, workdir=tmp_path)
    ev = task.evaluate({"alpha": -0.05, "omega_x": -3.0, "omega_z": 1.0, "v_z": -2.4}, ctx)
    for name in ("ppo.h5", "rollout.h5", "filmstrip.png"):
        assert (tmp_path / name).is_file(), name
    assert ev.metrics["samples"] >= 128 and ev.metrics["bar_height_reached"] >= 0.5
    assert "bar_height" in ev.history and len(ev.history["bar_height"]) == ev.metrics["iterations"]
    assert ev.failed or 0.0 <= ev.features[0] <= math.pi
    groups, _ = load(tmp_path / "ppo.h5")
    assert groups["counters"]["samples"] == ev.metrics["samples"]
    # a second call with the same workdir resumes: no new iteration, same policy, same history
    w0 = groups["policy"]
    ev2 = task.evaluate({"alpha": -0.05, "omega_x": -3.0, "omega_z": 1.0, "v_z": -2.4}, ctx)
    assert ev2.metrics["samples"] == ev.metrics["samples"]
    assert ev2.metrics["iterations"] == ev.metrics["iterations"]
    assert ev2.history["bar_height"] == ev.history["bar_height"]
    g2, _ = load(tmp_path / "ppo.h5")
    for k in w0:
        np.testing.assert_array_equal(np.asarray(w0[k]), np.asarray(g2["policy"][k]))
    assert ev2.metrics.get("strategy_angle", math.nan) == pytest.approx(ev.metrics.get("strategy_angle", math.nan), nan_ok=True)
    # the learning-curve reader sees the same iterations as the evaluation's history
    from jt_tasks.jumping.analysis import curves

    c = curves.read(tmp_path / "ppo.h5")
    assert len(c["samples"]) == ev.metrics["iterations"] and c["samples"][-1] == ev.metrics["samples"]
    assert list(c["bar_height"]) == [p[1] for p in ev.history["bar_height"]]
    times = [p[2] for p in ev.history["bar_height"]]  # each iteration with its own wall-clock time
    assert len(set(times)) == len(times) and times == sorted(times)
    assert curves.plot([c], ["tiny"], tmp_path / "curves.png").stat().st_size > 1000
    assert curves.table([c], ["tiny"]).count("| tiny |") == len(c["samples"])


# Stage 2 (task.stage=2): tests/plugins/jt_tasks/jumping/test_stage2.py


def test_the_paper_budget_says_its_cost_and_the_laptop_way():
    from toolkit.config import compose

    default = compose(["task=highjump", "search=bds"])
    assert "experiment=laptop" in default.cost and "six hours" in default.cost
    assert str(default.action.name) == "pvae" and str(default.action.prior) == "auto"  # runs as typed
    laptop = compose(["task=highjump", "search=bds", "experiment=laptop"])
    assert laptop.get("cost") is None and laptop.search.budget == 10 and laptop.curriculum.z_freeze == 0.5 and laptop.curriculum.z_min == 0.2


@pytest.mark.parametrize("enabled", [True, False])
def test_final_fallback_steps_down_one_dz_to_z_min(enabled):
    from toolkit import plugins

    task = plugins.load("task", "highjump")(_cfg(f"task.final_fallback={str(enabled).lower()}"))
    env = task.make_env(seed=0)
    try:
        task._fallback = (0.2, 0.15, "bar_height")
        env.bar_height = 0.5
        env.reset(seed=0)  # no step: the tracker has not crossed
        assert task.retry_rollout(env, {}) is enabled
        if enabled:
            env.reset(seed=0)
            assert env.difficulty == pytest.approx(0.35)
            assert task.retry_rollout(env, {}) and (env.reset(seed=0) or True)
            assert env.difficulty == pytest.approx(0.2)
            assert not task.retry_rollout(env, {})  # 0.05 would be below z_min
            env.tracker.land(0.1, np.array([0.0, 0.0, 0.0, 1.0]))
            env.bar_height = 0.5
            assert not task.retry_rollout(env, {})  # it crossed: keep the rollout
    finally:
        env.close()


@pytest.mark.parametrize("task", ["highjump", "obstacle", "longjump"])
def test_sim_control_hz_is_refused_by_the_jumps_whose_rate_is_the_curriculums(task):
    """``sim.control_hz`` means the same for every task: the jumps' rate is their curriculum's,
    so setting it is one line naming the curriculum's keys, not a value silently ignored."""
    from toolkit.config import compose
    from toolkit.errors import JtError

    with pytest.raises(JtError, match="curriculum.control_hz_start") as e:
        compose([f"task={task}", "sim.control_hz=60"])
    assert "\n" not in str(e.value)
    compose([f"task={task}", "sim.control_hz=30"])  # the default is no choice


def test_a_training_split_across_processes_equals_the_whole_one(tmp_path):
    """A resumed evaluation builds fresh environments; the uninterrupted one's have jumped into the
    bar before. Bar contacts used to reorder PyBullet's contact pairs for the later episodes, so a
    resume differed in the 7th digit; with deterministic pair order it is the same bit for bit."""
    import shutil

    from toolkit import plugins
    from toolkit.interfaces.task import EvalContext
    from toolkit.rl.checkpoint import load

    point = {"alpha": 0.39, "omega_x": -0.45, "omega_z": -0.9, "v_z": -1.3}  # touches the 0.5 m bar
    run = lambda n, d: plugins.load("task", "highjump")(_cfg(f"agent.total_samples={64 * n}")).evaluate(
        point, EvalContext(index=0, seed=3, workdir=d))
    whole = run(6, tmp_path / "whole")
    (tmp_path / "split").mkdir()
    run(3, tmp_path / "split")
    (tmp_path / "split" / "rollout.h5").unlink()
    split = run(6, tmp_path / "split")
    assert split.metrics["samples"] == whole.metrics["samples"] == 6 * 64
    a, b = load(tmp_path / "whole" / "ppo.h5")[0], load(tmp_path / "split" / "ppo.h5")[0]
    for k in a["policy"]:
        np.testing.assert_array_equal(np.asarray(a["policy"][k]), np.asarray(b["policy"][k]), err_msg=k)
    timing = {k for k in whole.metrics if k.endswith("_s") or "per_s" in k or "wall" in k}
    assert set(split.metrics) == set(whole.metrics) and "strategy_angle" in whole.metrics
    same = lambda m: {k: (None if v != v else v) for k, v in m.items() if k not in timing}  # NaN as None
    assert same(split.metrics) == same(whole.metrics)  # every metric, ==
    assert split.features == whole.features
    shutil.rmtree(tmp_path / "split")
