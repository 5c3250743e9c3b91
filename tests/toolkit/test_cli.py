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
