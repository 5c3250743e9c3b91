"""``jt bench rollout`` runs end to end and its breakdown adds up (no timing is asserted: speed is
measured by the benchmark itself, docs/performance.md): the task's own configuration by default (an
action space that needs a prior replaced by raw), resets timed apart from steps, and training's
speed read from a real ``jt run``'s ``ppo.h5``."""

from __future__ import annotations

import json

import numpy as np
import pytest

from typer.testing import CliRunner

from tests.conftest import run_jt


def test_bench_rollout_reports_the_breakdown_and_collection(tmp_path):
    from toolkit.cli import app

    out = tmp_path / "bench.json"
    res = CliRunner().invoke(app, ["bench", "rollout", "--steps", "20", "--collect-steps", "2", "--workers", "1",
                                   "--rates", "10", "--repeats", "2", "--train-iterations", "0", "--json", str(out)])
    assert res.exit_code == 0, res.output
    assert "physics share" in res.output and "samples/s" in res.output
    # highjump's own config, its P-VAE action (which needs a prior) replaced by raw, and said so
    assert "task=highjump action=raw (pvae needs a prior) sim.loop=auto (task's own: spd=maba)" in res.output
    data = json.loads(out.read_text())["results"][0]
    assert data["overrides"] == ["action=raw", "sim.loop=auto"] and data["training"] == []
    env = data["env"][0]
    assert env["resets"] >= 1 and env["us_per_reset"] > 0 and env["us_per_step"] > 0
    assert env["reset_in_steps"] == pytest.approx(env["us_per_reset"] / env["us_per_step"])
    assert "control steps of" in res.output  # the reset line under the rate's row
    parts = env["us_physics"] + env["us_spd"] + env["us_io"] + env["us_checks"] + env["us_env"]
    assert abs(parts - env["us_total"]) <= 0.05 * env["us_total"]  # the parts make up the whole (the median of 2 is the mean)
    a, b = env["physics_shares"]  # two fresh envs measured; the share shown is their median
    assert min(a, b) <= env["physics_share"] <= max(a, b) and "(median of" in res.output
    assert 0.0 < env["physics_share"] < 1.0 and env["substeps"] >= 20 * 60 * 0.5
    col = data["collection"][0]
    assert col["samples_per_s"] > 0 and 0 < col["peak_rss_mb"] < 4096


def test_bench_rollout_rejects_bad_input():
    """Each mistake is one ``jt: ...`` line on stderr and status 2, before any work (through the CLI)."""
    cases = [(["--spd", "lu"], "lu"), (["--spd", "maba,df"], "one backend"), (["--rates", "0"], "--rates"),
             (["--workers", "x"], "--workers"), (["--workers", "0"], "--workers"), (["--repeats", "0"], "--repeats"),
             (["--steps", "-1"], "--steps"), (["--train-iterations", "-1"], "--train-iterations"),
             (["--train-workers", "0"], "--train-workers"), (["--action", "nope"], "--action"),
             (["--tasks", "nope"], "spacetime"), (["--tasks", "zdt1"], "spacetime"),  # the policy tasks named
             (["--tasks", "spacetime", "agent.nope=1"], "nope"), (["--train-iteration", "1"], "--train-iteration")]
    for args, said in cases:
        res = run_jt("bench", "rollout", *args, timeout=120)
        assert res.returncode == 2, (args, res.stdout, res.stderr)
        lines = res.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("jt: ") and said in lines[0], (args, res.stderr)
        assert "Traceback" not in res.stderr and "measuring" not in res.stdout, (args, res.stdout)
    zdt1 = run_jt("bench", "rollout", "--tasks", "zdt1").stderr
    assert "trains no policy" in zdt1 and "getup" in zdt1 and "zdt1" not in zdt1.split(":", 2)[-1]


def test_task_overrides_keep_the_tasks_own_config_unless_asked():
    from toolkit.rl.rollout_bench import task_overrides

    over, header = task_overrides("getup", extra=["sim.loop=auto"])
    assert over == ["action=raw", "sim.loop=auto"]  # no spd override: the task's own
    assert header.startswith("task=getup action=raw (cvae needs a prior) sim.loop=auto")
    over, header = task_overrides("spacetime")
    assert over == [] and header == "task=spacetime (task's own: action=ffc_fbc, spd=df)"
    over, header = task_overrides("highjump", action="pvae", spd="maba")  # asked for: no fallback, no note
    assert over == ["action=pvae", "spd=maba"] and header == "task=highjump action=pvae spd=maba"


def test_env_breakdown_times_resets_apart_from_steps():
    """Real PyBullet, the spacetime env: every reset timed apart from the steps, the figures consistent."""
    from toolkit import plugins
    from toolkit.config import compose
    from toolkit.rl.rollout_bench import env_breakdown, median_breakdown

    task = plugins.load("task", "spacetime")(compose(["task=spacetime"]))
    row = env_breakdown(lambda: task.make_env(seed=0), 30.0, control_steps=12)
    assert row["resets"] >= 1 and row["us_per_reset"] > 0 and row["us_per_step"] > 0
    assert row["reset_in_steps"] == pytest.approx(row["us_per_reset"] / row["us_per_step"], rel=1e-12)
    assert row["reset_us_per_sample_L5"] == pytest.approx(row["us_per_reset"] / 5, rel=1e-12)
    assert row["reset_us_per_sample_L600"] == pytest.approx(row["us_per_reset"] / 600, rel=1e-12)
    assert 0 < row["reset_share"] < 1
    # steps and resets are parts of the whole timed run (the per-substep figures are over it, as before)
    whole = 12 / row["control_steps_per_s"] * 1e6
    assert row["us_per_step"] * 12 + row["us_per_reset"] * row["resets"] <= whole * 1.001
    assert row["us_total"] * row["substeps"] == pytest.approx(whole, rel=1e-9)
    med = median_breakdown(lambda: task.make_env(seed=0), 30.0, control_steps=12, repeats=2)
    assert med["reset_in_steps"] == pytest.approx(med["us_per_reset"] / med["us_per_step"], rel=1e-12)


def test_bench_rollout_with_training_through_the_cli(tmp_path):
    """The whole command with a training measurement: JSON holds env (reset figures), collection
    and training rows."""
    out = tmp_path / "bench.json"
    res = run_jt("bench", "rollout", "--tasks", "spacetime", "--rates", "30", "--steps", "20", "--repeats", "1",
                 "--workers", "1", "--collect-steps", "2", "--train-iterations", "2", "--train-workers", "1",
                 "--json", str(out), "agent.samples_per_iteration=256", "agent.minibatch_size=64", timeout=600)
    assert res.returncode == 0, res.stderr
    assert "PPO training as jt run" in res.stdout and "task=spacetime sim.loop=auto" in res.stdout
    data = json.loads(out.read_text())["results"][0]
    assert data["env"][0]["us_per_reset"] > 0 and data["collection"][0]["samples_per_s"] > 0
    (row,) = data["training"]
    assert row["n_workers"] == 1 and row["collect_share"] + row["update_share"] == pytest.approx(1.0)


def test_collection_workers_get_the_spec_built_once_as_training_does():
    """The bench's ``env_fn`` carries the policy task's env class and the spec made by the driver
    (what ``toolkit.policy.train.EnvFactory`` gives a training run's workers): a worker does not
    compose the task or build the spec again, so its memory is a training worker's."""
    import pickle

    from toolkit import plugins
    from toolkit.config import compose
    from toolkit.rl.rollout_bench import _EnvFn

    task = plugins.load("task", "highjump")(compose(["task=highjump", "action=raw"]))
    fn = pickle.loads(pickle.dumps(_EnvFn("highjump", ["action=raw"], task)))
    assert fn._task is None and fn._made is not None and fn._made[0] is task.env_class
    assert fn._made[1] == task.env_spec({})
    env, composed = fn(3), task.make_env(seed=3)
    try:
        assert fn._task is None  # built from the shipped spec, nothing composed
        np.testing.assert_array_equal(env.reset(seed=5)[0], composed.reset(seed=5)[0])
    finally:
        env.close()
        composed.close()
