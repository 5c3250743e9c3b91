"""The run lifecycle's staged config (``toolkit.execution.lifecycle``): a run killed between its
row and the move of its config resumes from the staged file; stale staged files are swept, unless
a run still names them."""

from __future__ import annotations

import os
import subprocess
import sys
import time

from tests.conftest import jt_env


def _killed_at_row_birth(tmp_path):
    """A zdt1 run as a kill right after ``start_run`` leaves it: a RUNNING row whose config is
    only the staged file its tag names."""
    from toolkit import plugins
    from toolkit.config import compose, to_yaml
    from toolkit.execution import describe, lifecycle
    from toolkit.store import atomic
    from toolkit.store.tracking import Store

    store_dir = tmp_path / "store"
    cfg = compose(["task=zdt1", "experiment=smoke", f"store={store_dir}"])
    store = Store(str(store_dir))
    describe.ensure_experiment(store, "zdt1", plugins.load("task", "zdt1"))
    token = "a" * 32
    atomic.write_text(lifecycle._staged_path(store, token), to_yaml(cfg))
    rid = store.start_run("zdt1", run_name="zdt1·random·seed0",
                          tags={lifecycle.STAGED_TAG: token, "jt.task": "zdt1", "jt.search": str(cfg.search.name)})
    return store, rid, token


def test_a_run_killed_before_its_config_moved_resumes(tmp_path):
    store, rid, token = _killed_at_row_birth(tmp_path)
    assert not (store.workdir(rid) / "config.yaml").exists()
    out = subprocess.run([sys.executable, "-m", "toolkit.cli", "run", f"resume={rid}", f"store={store.root}"],
                         capture_output=True, text=True, env=jt_env(), timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    run = store.get_run(rid)
    assert run.info.status == "FINISHED" and run.data.params.get("task.name") == "zdt1"
    assert (store.workdir(rid) / "config.yaml").is_file()


def test_stale_staged_configs_are_swept_unless_a_run_names_them(tmp_path):
    from toolkit.execution import lifecycle

    store, rid, token = _killed_at_row_birth(tmp_path)
    named = lifecycle._staged_path(store, token)
    orphan = lifecycle._staged_path(store, "b" * 32)
    orphan.write_text("task: {}\n")
    temp = orphan.with_name(orphan.name + ".tmp-123")
    temp.write_text("")
    fresh = lifecycle._staged_path(store, "c" * 32)
    fresh.write_text("task: {}\n")
    old = time.time() - 2 * lifecycle.STALE_STAGED_S
    for f in (named, orphan, temp):
        os.utime(f, (old, old))
    lifecycle._sweep_staged(store)
    assert named.exists() and fresh.exists()  # a run needs the first; the last may be a run starting now
    assert not orphan.exists() and not temp.exists()
