"""``jt bench rollout`` runs end to end and its breakdown adds up (no timing is asserted: speed is
measured by the benchmark itself, docs/performance.md)."""

from __future__ import annotations

import json

import numpy as np

from typer.testing import CliRunner


def test_bench_rollout_reports_the_breakdown_and_collection(tmp_path):
    from toolkit.cli import app

    out = tmp_path / "bench.json"
    res = CliRunner().invoke(app, ["bench", "rollout", "--steps", "20", "--collect-steps", "2", "--workers", "1",
                                   "--rates", "10", "--repeats", "2", "--json", str(out)])
    assert res.exit_code == 0, res.output
    assert "physics share" in res.output and "samples/s" in res.output
    data = json.loads(out.read_text())["results"][0]
    env = data["env"][0]
    parts = env["us_physics"] + env["us_spd"] + env["us_io"] + env["us_checks"] + env["us_env"]
    assert abs(parts - env["us_total"]) <= 0.05 * env["us_total"]  # the parts make up the whole (the median of 2 is the mean)
    a, b = env["physics_shares"]  # two fresh envs measured; the share shown is their median
    assert min(a, b) <= env["physics_share"] <= max(a, b) and "(median of" in res.output
    assert 0.0 < env["physics_share"] < 1.0 and env["substeps"] >= 20 * 60 * 0.5
    col = data["collection"][0]
    assert col["samples_per_s"] > 0 and 0 < col["peak_rss_mb"] < 4096


def test_bench_rollout_rejects_bad_input():
    import subprocess
    import sys

    for args in (["--spd", "lu"], ["--spd", "maba,df"], ["--rates", "0"], ["--workers", "x"], ["--tasks", "nope"],
                 ["--repeats", "0"]):
        res = subprocess.run([sys.executable, "-c", "from toolkit.cli import main; main()", "bench", "rollout", *args],
                             capture_output=True, text=True, timeout=120)
        assert res.returncode == 2, (args, res.stdout, res.stderr)
        lines = [ln for ln in res.stderr.splitlines() if ln.startswith("jt:")]
        assert len(lines) == 1 and "Traceback" not in res.stderr, res.stderr


def test_collection_workers_get_the_spec_built_once_as_training_does():
    """The bench's ``env_fn`` carries the policy task's env class and the spec made by the driver
    (what ``jt_tasks.policy.train.EnvFactory`` gives a training run's workers): a worker does not
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
