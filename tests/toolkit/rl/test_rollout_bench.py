"""``jt bench rollout`` runs end to end and its breakdown adds up (no timing is asserted: speed is
measured by the benchmark itself, docs/performance.md)."""

from __future__ import annotations

import json

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
