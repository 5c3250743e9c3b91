"""``jt bench spd`` takes its lists from the registry and the simulator plugin (issue 54: the core
names no plugin): every installed SPD backend is accepted, the valid choices come from there."""

from tests.conftest import run_jt


def test_an_installed_backend_the_core_never_listed_is_timed():
    """``spd=servo`` (constraint motors, no solve to time) was refused when the core kept its own
    list; now it is one of the installed backends and gets a row with a step time."""
    p = run_jt("bench", "spd", "--models", "humanoid", "--backends", "servo", "--samples", "3")
    assert p.returncode == 0, p.stderr
    rows = [ln.split() for ln in p.stdout.splitlines() if ln.startswith("humanoid")]
    assert [r[3] for r in rows] == ["servo"]
    assert rows[0][4] == "nan" and float(rows[0][5]) > 0  # no solve time, a measured step
    assert "pybullet build time" not in p.stdout + p.stderr


def test_bad_lists_are_one_line_naming_the_installed_choices():
    p = run_jt("bench", "spd", "--backends", "nope")
    assert p.returncode == 2 and "Traceback" not in p.stderr
    line = p.stderr.strip()
    assert len(line.splitlines()) == 1 and line.startswith("jt: unknown backend 'nope'; choose from: ")
    assert {"maba", "df", "sf", "pcg", "bullet", "servo"} <= set(line.split(": ")[-1].split(", "))
    p = run_jt("bench", "spd", "--models", "robot")
    assert p.returncode == 2
    assert p.stderr.strip().startswith("jt: unknown model 'robot'; choose from: ") and "snake36" in p.stderr
    p = run_jt("bench", "spd", "--sim", "nosuch")
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and "bullet" in p.stderr


def test_bench_rollout_refuses_what_jt_run_would_before_measuring(tmp_path):
    """A NaN rate, a rate that does not divide 600 Hz into whole substeps, no collection steps and
    an unwritable --json are one line each, before any measurement (the --json one used to come
    after the whole benchmark)."""
    cases = {("--rates", "nan"): "--rates takes positive control rates",
             ("--rates", "85.71"): "divide it into whole substeps",
             ("--collect-steps", "0"): "--collect-steps must be >= 1",
             ("--json", str(tmp_path / "a_file" / "x.json")): "cannot write there"}
    (tmp_path / "a_file").write_text("not a folder")
    for args, says in cases.items():
        p = run_jt("bench", "rollout", *args)
        assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1, (args, p.stderr)
        assert says in p.stderr and "measuring" not in p.stdout, (args, p.stdout)


def test_bench_spd_checks_its_output_paths_first(tmp_path):
    p = run_jt("bench", "spd", "--models", "humanoid", "--json", str(tmp_path))
    assert p.returncode == 2 and "--json" in p.stderr and "is a folder" in p.stderr and "model" not in p.stdout
