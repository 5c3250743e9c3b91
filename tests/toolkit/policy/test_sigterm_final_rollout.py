"""SIGTERM while a policy task rolls out its trained policy (issue 30): the request is recorded, the
run stops at its next safe point, exits 130 with the run KILLED and nothing RUNNING, and a resume
ends with exactly the metrics of an uninterrupted run of the same seed."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

from tests.conftest import jt_env, run_jt, store_query

COMMON = ("run", "task=runup", "experiment=smoke", "seed=0")


_query = store_query


def _outer(store: Path) -> tuple[str, str]:
    return _query(store, "select run_uuid, status from runs r where not exists (select 1 from tags t where "
                         "t.run_uuid = r.run_uuid and t.key = 'mlflow.parentRunId')")[0]


def _metrics(store: Path, rid: str) -> dict[str, float]:
    return dict(_query(store, "select key, value from latest_metrics where run_uuid = ?", rid))


def _trained(store: Path, total: int) -> bool:
    """True once an evaluation's checkpoint holds the whole budget: training is over, the final
    rollout of the trained policy is what runs now."""
    from toolkit.rl.checkpoint import load

    for path in store.glob("work/*/eval_*/ppo.h5"):
        try:
            if int(load(path)[0]["counters"]["samples"]) >= total:
                return True
        except (OSError, KeyError, ValueError):  # written while we read it
            pass
    return False


def test_sigterm_in_the_final_rollout_stops_killed_and_resumes_to_the_same_result(tmp_path):
    from toolkit.config import compose

    total = int(compose(["task=runup", "experiment=smoke"]).agent.total_samples)
    ref_store, store = tmp_path / "ref", tmp_path / "store"
    ref = run_jt(*COMMON, f"store={ref_store}")
    assert ref.returncode == 0, ref.stderr[-2000:]
    proc = subprocess.Popen([sys.executable, "-m", "toolkit.cli", *COMMON, f"store={store}"], env=jt_env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 300
    while not _trained(store, total) and proc.poll() is None and time.time() < deadline:
        time.sleep(0.02)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert "Traceback" not in err and "Exception ignored" not in err and "internal error" not in err, err
    rid, status = _outer(store)
    assert proc.returncode == 130 and status == "KILLED", (proc.returncode, status, err[-1500:])
    assert _query(store, "select name from runs where status = 'RUNNING'") == []
    again = run_jt("run", f"resume={rid}", f"store={store}")
    assert again.returncode == 0, again.stderr[-2000:]
    assert _outer(store) == (rid, "FINISHED")
    ref_id, _ = _outer(ref_store)
    want, got = _metrics(ref_store, ref_id), _metrics(store, rid)
    clock = {k for k in want if any(w in k for w in ("seconds", "per_s", "wall"))}  # wall-clock figures
    assert len(want) > len(clock) and {k: got.get(k) for k in set(want) - clock} == {k: want[k] for k in set(want) - clock}
