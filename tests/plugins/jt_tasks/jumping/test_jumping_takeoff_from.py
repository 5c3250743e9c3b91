"""``task.takeoff_from``: a jump starts from a run-up's ``takeoff_state.h5`` (``000`` §6.1.1)."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import make_spec


@pytest.fixture(scope="module")
def runup_file(tmp_path_factory):
    """A ``takeoff_state.h5`` as ``task=runup`` writes it, from a state with known features."""
    from jt_tasks.runup.reward import measure
    from jt_tasks.takeoff.state import takeoff_state
    from jt_tasks.takeoff.state_file import NAME, write_takeoff_state

    ts = takeoff_state({"omega_x": -1.0, "omega_z": 0.5, "v_z": -1.5})
    q, qd = ts.q.copy(), ts.qd.copy()
    q[:3] += [4.0, 0.0, -2.0]  # somewhere else on the ground, as a run-up ends
    folder = tmp_path_factory.mktemp("runup")
    write_takeoff_state(folder / NAME, q, qd, measure(q, qd), {"omega_x": -1.0, "omega_z": 0.5, "v_z": -1.5},
                        "right", "highjump", 0.1, 0.9)
    return folder / NAME


def test_the_env_starts_from_the_files_state_with_the_jumping_intention(runup_file):
    from jt_tasks.jumping.env import JumpEnv
    from jt_tasks.takeoff.state import facing_velocities

    for v_y in (None, 2.06):
        env = JumpEnv(make_spec(takeoff_file=str(runup_file), v_y=v_y), seed=0)
        try:
            env.reset(seed=0)
            q, qd = env.sim.state()
            v, w = facing_velocities(q, qd)
            np.testing.assert_allclose(w, [-1.0, 3.0, 0.5], atol=1e-6)  # the file's, not make_spec's features
            assert v[2] == pytest.approx(-1.5, abs=1e-6)
            assert v[1] == pytest.approx(2.06 if v_y else env.takeoff.qd[1], abs=1e-6)
            assert q[0] == pytest.approx(0.0, abs=1e-9)  # re-placed in front of the suite
        finally:
            env.close()


def test_task_fixes_the_achieved_features_and_searches_only_alpha(runup_file):
    from omegaconf import OmegaConf

    from jt_tasks.jumping.task import HighJumpTask

    task = HighJumpTask(OmegaConf.create({"task": {"name": "highjump", "takeoff_from": str(runup_file.parent)}}))
    assert list(task.problem().space.names) == ["alpha"]
    spec = task.env_spec({"alpha": 0.3})
    assert spec.takeoff_file == str(runup_file)
    assert spec.features["omega_x"] == pytest.approx(-1.0, abs=1e-6) and spec.features["alpha"] == 0.3


def test_takeoff_from_a_run_id_in_a_real_store(runup_file, tmp_path):
    from omegaconf import OmegaConf

    from jt_tasks.jumping.task import HighJumpTask
    from toolkit.store.tracking import Store

    store = Store(tmp_path)
    outer = store.start_run("runup")
    for i, goal in enumerate((0.2, 0.9)):  # the outer run resolves to its best evaluation
        kid = store.start_run("runup", parent_run_id=outer, tags={"jt.eval_index": str(i)})
        store.log_artifact(kid, runup_file)
        with store.metrics(kid) as buf:
            buf.add("goal_reward", goal)
        store.end_run(kid)
        best = kid if goal == 0.9 else None
    store.end_run(outer)
    cfg = OmegaConf.create({"task": {"name": "highjump", "takeoff_from": outer}, "store": str(tmp_path)})
    assert HighJumpTask(cfg).takeoff_file() == store.artifact_dir(best) / "takeoff_state.h5"


@pytest.mark.parametrize("ref, message", [("nope", "no such run"), ("/no/where", "no takeoff_state.h5 there")])
def test_bad_takeoff_from_is_one_line(ref, message, tmp_path):
    from omegaconf import OmegaConf

    from jt_tasks.jumping.task import HighJumpTask
    from toolkit.errors import JtError

    cfg = OmegaConf.create({"task": {"name": "highjump", "takeoff_from": ref}, "store": str(tmp_path)})
    with pytest.raises(JtError, match=message) as e:
        HighJumpTask(cfg).problem()
    assert "\n" not in str(e.value)


def test_the_take_off_foot_must_match(runup_file):
    from jt_tasks.jumping.env import JumpEnv
    from toolkit.errors import JtError

    with pytest.raises(JtError, match="right foot.*task.foot=left"):
        JumpEnv(make_spec(takeoff_file=str(runup_file), foot="left"), seed=0)
