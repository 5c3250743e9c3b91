"""The task: its search problem, and ``jt run task=runup experiment=smoke`` end to end."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import run_jt


def _task(*overrides):
    from toolkit import plugins
    from toolkit.config import compose

    return plugins.load("task", "runup")(compose(["task=runup", "experiment=smoke", *overrides]))


def test_problem_is_the_jump_tasks_take_off_box():
    pr = _task().problem()
    assert pr.space.names == ["omega_x", "omega_z", "v_z"]  # no alpha: eq 13 has none
    assert pr.space.defaults() == [-3.0, 1.0, -2.40]  # Fosbury flop, 000 Table 3
    assert [(p.low, p.high) for p in pr.space.params] == [(-3.0, 3.0), (-3.0, 3.0), (-2.5, -0.5)]  # highjump.yaml
    ob = _task("task.kind=obstacle").problem()
    assert ob.space.names == ["omega_x", "omega_y", "omega_z"]
    assert ob.space.defaults() == [0.0, 0.0, 1.0]  # Straddle, 000 Table 4
    fixed = _task("+task.point.v_z=-1.0", "+task.ranges.omega_x=[-1.0,1.0]").problem()
    assert fixed.space.names == ["omega_x", "omega_z"] and fixed.space.params[0].high == 1.0
    from toolkit.errors import JtError

    with pytest.raises(JtError):
        _task("task.kind=longjump")


def test_jt_run_smoke_writes_a_takeoff_state_that_reproduces_its_features(store_dir):
    import h5py

    from jt_tasks.runup.reward import goal_reward
    from jt_tasks.takeoff.state import facing_velocities
    from jt_tasks.takeoff.state_file import read_takeoff_state

    proc = run_jt("run", "task=runup", "experiment=smoke", f"store={store_dir}", timeout=240)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    out = proc.stdout
    assert "FINISHED" in out and "goal_reward=" in out and "imitation_reward=" in out and "took_off=1" in out
    files = list(Path(store_dir).rglob("takeoff_state.h5"))
    assert files, "no takeoff_state.h5 in the store"
    for name in ("ppo.h5", "rollout.h5", "filmstrip.png"):
        assert list(Path(store_dir).rglob(name)), name
    with h5py.File(files[0], "r") as f:
        q, qd = f["q"][()], f["qd"][()]
        qw, qdw = f["q_world"][()], f["qd_world"][()]
        feats = {k: float(f["features"][k][()]) for k in f["features"]}
        targets = {k: float(f["target_features"][k][()]) for k in f["target_features"]}
        r_goal = float(f["r_goal"][()])
        assert f["foot"][()].decode() == "right" and f["kind"][()].decode() == "highjump"
    assert q.shape == (43,) and qd.shape == (34,)
    assert targets == {"omega_x": -3.0, "omega_z": 1.0, "v_z": -2.4, "omega_y": 3.0}
    for qq, vv in ((q, qd), (qw, qdw)):  # the facing-frame features do not depend on the heading
        v, w = facing_velocities(qq, vv)
        np.testing.assert_allclose([w[0], w[1], w[2], v[2]],
                                   [feats["omega_x"], feats["omega_y"], feats["omega_z"], feats["v_z"]], atol=1e-9)
    assert r_goal == pytest.approx(goal_reward("highjump", feats, targets))
    assert 0.0 < r_goal <= 1.0 and math.isfinite(r_goal)
    # the jumping convention: heading along +x, root above the origin
    assert q[0] == 0.0 and q[2] == 0.0
    np.testing.assert_allclose(np.linalg.norm(q[3:7]), 1.0, atol=1e-12)
    st = read_takeoff_state(files[0])
    assert st.foot == "right" and st.features == feats
    np.testing.assert_array_equal(st.q, q)
