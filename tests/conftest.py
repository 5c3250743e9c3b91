"""Shared fixtures: a temp store, and the third-party example plugin installed into a temp dir.

No test module goes directly in tests/plugins/ (tests/toolkit/testing/test_test_layout.py says why).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FIXTURE_PLUGIN = ROOT / "tests" / "fixtures" / "jt_example_plugin"


@pytest.fixture(scope="session")
def example_plugin_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """jt-example-plugin installed with pip into a private target directory (a real install), built
    from a copy so that test workers running side by side never share a ``build/`` folder."""
    src = tmp_path_factory.mktemp("example_src") / FIXTURE_PLUGIN.name
    shutil.copytree(FIXTURE_PLUGIN, src, ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"))
    target = tmp_path_factory.mktemp("site")
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "--no-deps", "--no-build-isolation", "-q",
         "--disable-pip-version-check", "--target", str(target), str(src)],
        check=True, capture_output=True,
    )
    return target


@pytest.fixture()
def example_plugin(example_plugin_dir: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The example plugin importable and discoverable in this process."""
    from toolkit import plugins

    monkeypatch.syspath_prepend(str(example_plugin_dir))
    plugins.refresh()
    yield example_plugin_dir
    plugins.refresh()


@pytest.fixture()
def store_dir(tmp_path: Path) -> Path:
    """An empty store root."""
    return tmp_path / "store"


def jt_env(extra_path: Path | None = None) -> dict[str, str]:
    """Environment for running the ``jt`` command in a subprocess."""
    env = dict(os.environ)
    env.pop("JT_STORE", None)
    if extra_path is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(extra_path), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    return env


def run_jt(*args: str, extra_path: Path | None = None, cwd: Path | None = None,
           timeout: float = 300) -> subprocess.CompletedProcess:
    """Run ``jt ARGS`` as a user would; returns the completed process (text output)."""
    return subprocess.run([sys.executable, "-m", "toolkit.cli", *args], capture_output=True, text=True,
                          env=jt_env(extra_path), cwd=cwd, timeout=timeout)


def one_line_error(p: subprocess.CompletedProcess, code: int = 2) -> str:
    """The one ``jt: ...`` line a refused command printed (exit ``code``, no traceback)."""
    assert p.returncode == code, p.stderr[-500:]
    err = p.stderr.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in p.stderr and "internal error" not in err, err
    assert err.startswith("jt: ")
    return err


def store_query(store: Path, sql: str, *params: object) -> list[tuple]:
    """Rows of ``sql`` on a store's ``mlflow.db`` read directly (what a run left behind, even while
    it runs); ``[]`` while a writer holds the lock or before the tables exist."""
    import sqlite3

    con = sqlite3.connect(Path(store) / "mlflow.db", timeout=30)
    try:
        return con.execute(sql, params).fetchall()
    except sqlite3.OperationalError:  # locked by a writer, or a table not there yet
        return []
    finally:
        con.close()


@pytest.fixture()
def one_torch_thread():
    """One torch thread for a learner with small nets on 2 shared cores (restored afterwards)."""
    import torch

    n = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(n)


_SESSION: dict[str, int] = {}


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """Keep the session's exit status for ``pytest_unconfigure``."""
    _SESSION["status"] = int(exitstatus)


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config: pytest.Config) -> None:
    """End the test process with pytest's own exit status once every report is written, skipping
    interpreter finalisation: a clean clone's full run once passed every test and then died in a
    segmentation fault at exit (2026-12-06, rc 139; the kernel log places it in a background
    thread, as C extensions' threads that outlive the interpreter (Ray's core worker, gRPC) can),
    which would turn a green suite red. ``JT_TEST_FINALIZE=1`` lets Python finalise normally.
    Only the controlling process ends this way: a pytest-xdist worker (``config.workerinput``) hands
    its reports to the controller over a channel that must be closed normally."""
    if hasattr(config, "workerinput"):
        return
    if "status" in _SESSION and os.environ.get("JT_TEST_FINALIZE") != "1":
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_SESSION["status"])
