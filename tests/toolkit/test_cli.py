"""The jt command as a user meets it: fast help, one-line errors with exit status 2."""

import subprocess
import sys

from tests.conftest import run_jt


def test_help_imports_nothing_heavy():
    code = (
        "import sys\n"
        "sys.argv = ['jt', '--help']\n"
        "from toolkit import cli\n"
        "try:\n"
        "    cli.main()\n"
        "except SystemExit:\n"
        "    pass\n"
        "print('HEAVY:' + ','.join(m for m in ('torch','pybullet','mlflow','numpy','sklearn') if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert "run" in out.stdout and "compare" in out.stdout
    assert out.stdout.strip().splitlines()[-1] == "HEAVY:", out.stdout[-300:]


def test_unknown_search_exits_2_with_choices():
    p = run_jt("run", "search=bdx", "experiment=smoke")
    assert p.returncode == 2
    assert p.stderr.strip().startswith("jt: unknown search 'bdx'; choose one of: ")
    assert len(p.stderr.strip().splitlines()) == 1 and "Traceback" not in p.stderr


def test_plugins_command_lists_third_party_and_broken(example_plugin_dir):
    p = run_jt("plugins", extra_path=example_plugin_dir)
    assert p.returncode == 0, p.stderr
    lines = p.stdout.splitlines()
    assert lines[0].split()[:3] == ["KIND", "NAME", "DISTRIBUTION"]
    assert any(ln.split()[:3] == ["task", "quadratic", "jt-example-plugin"] for ln in lines)
    assert any("broken_example" in ln and "BROKEN" in ln for ln in lines)
    p = run_jt("plugins", "searchers")
    assert p.returncode == 0 and all(ln.startswith(("KIND", "search")) for ln in p.stdout.splitlines())
    p = run_jt("plugins", "nope")
    assert p.returncode == 2 and "choose one of" in p.stderr


def test_run_show_and_bad_run_id(example_plugin_dir, tmp_path):
    store = tmp_path / "s"
    p = run_jt("run", "task=quadratic", f"store={store}", extra_path=example_plugin_dir)
    assert p.returncode == 0, p.stderr
    run_id = p.stdout.split()[1]
    assert "FINISHED" in p.stdout
    s = run_jt("show", run_id, f"store={store}", extra_path=example_plugin_dir)
    assert s.returncode == 0 and "[FINISHED]" in s.stdout and "evaluation.h5" in s.stdout
    bad = run_jt("show", "deadbeef", f"store={store}")
    assert bad.returncode == 2 and bad.stderr.startswith("jt: no run 'deadbeef'")


def _one_line(p, code=2):
    assert p.returncode == code, p.stderr[-300:]
    assert len(p.stderr.strip().splitlines()) == 1 and "Traceback" not in p.stderr and "internal error" not in p.stderr
    return p.stderr.strip()


def test_command_line_mistakes_are_one_line_with_the_valid_choices():
    assert "Valid: spd, ppo, rollout" in _one_line(run_jt("bench", "nope"))
    assert "Valid: run, compare" in _one_line(run_jt("nope"))
    assert "--seeds" in _one_line(run_jt("compare", "task=zdt1", "--seeds", "abc"))


def test_bad_stores_are_one_line_and_never_created(tmp_path):
    afile = tmp_path / "afile"
    afile.write_text("x")
    assert "is a file, not a folder" in _one_line(run_jt("run", "task=zdt1", "experiment=smoke", f"store={afile}"))
    (tmp_path / "corrupt").mkdir()
    (tmp_path / "corrupt" / "mlflow.db").write_bytes(b"not a database at all, not even close")
    msg = _one_line(run_jt("run", "task=zdt1", "experiment=smoke", f"store={tmp_path / 'corrupt'}"))
    assert "not an SQLite database" in msg
    assert not (tmp_path / "corrupt" / "runs").exists()
    missing = tmp_path / "nowhere"
    assert "no jt store at" in _one_line(run_jt("show", "deadbeef", f"store={missing}"))
    assert "no jt store at" in _one_line(run_jt("run", "resume=deadbeef", f"store={missing}"))
    assert not missing.exists()  # reading commands never create a store
