"""``takeoff_state.h5`` (``jt_tasks.takeoff.state_file``) and finding / loading it for a jump
(``jt_tasks.takeoff.source``), without the jump environment."""

from __future__ import annotations

import numpy as np
import pytest

FEATURES = {"omega_x": -1.0, "omega_z": 0.5, "v_z": -1.5}


@pytest.fixture(scope="module")
def state_file(tmp_path_factory):
    """A ``takeoff_state.h5`` written from a clip state moved away from the origin."""
    from jt_tasks.takeoff.state import facing_velocities, takeoff_state
    from jt_tasks.takeoff.state_file import NAME, write_takeoff_state

    ts = takeoff_state(FEATURES)
    q, qd = ts.q.copy(), ts.qd.copy()
    q[:3] += [4.0, 0.0, -2.0]
    v, w = facing_velocities(q, qd)
    measured = {"omega_x": w[0], "omega_y": w[1], "omega_z": w[2], "v_z": v[2]}
    path = tmp_path_factory.mktemp("runup") / NAME
    write_takeoff_state(path, q, qd, measured, FEATURES, "right", "highjump", 0.1, 0.9)
    return path


def test_the_file_reads_back_as_a_takeoff_state(state_file):
    import h5py

    from jt_tasks.takeoff.state import facing_velocities
    from jt_tasks.takeoff.state_file import read_takeoff_state

    ts = read_takeoff_state(state_file)
    assert ts.foot == "right" and ts.time == pytest.approx(0.1)
    assert ts.q[0] == 0.0 and ts.q[2] == 0.0  # heading-normalised, above the origin
    v, w = facing_velocities(ts.q, ts.qd)
    np.testing.assert_allclose([w[0], w[2], v[2]], [-1.0, 0.5, -1.5], atol=1e-9)
    assert ts.features["omega_x"] == pytest.approx(-1.0, abs=1e-9)
    with h5py.File(state_file, "r") as f:
        assert f["q_world"][0] == pytest.approx(4.0) and float(f["r_goal"][()]) == pytest.approx(0.9)
        assert f.attrs["format"] in ("jt.runup.takeoff_state/1", b"jt.runup.takeoff_state/1")


def test_load_imposes_v_y_and_checks_the_foot(state_file):
    from jt_tasks.takeoff import source
    from jt_tasks.takeoff.state import facing_velocities
    from toolkit.errors import JtError

    plain = source.load(state_file, "right", None)
    lifted = source.load(state_file, "right", 2.06)
    v0, w0 = facing_velocities(plain.q, plain.qd)
    v1, w1 = facing_velocities(lifted.q, lifted.qd)
    assert v1[1] == pytest.approx(2.06, abs=1e-9)
    np.testing.assert_allclose(w1, w0, atol=1e-9)
    np.testing.assert_allclose([v1[0], v1[2]], [v0[0], v0[2]], atol=1e-9)
    with pytest.raises(JtError, match="right foot.*task.foot=left"):
        source.load(state_file, "left", None)


def test_features_keeps_the_task_names_only(state_file):
    from jt_tasks.takeoff import source

    got = source.features(state_file, ("alpha", "omega_x", "omega_z", "v_z"))
    assert sorted(got) == ["omega_x", "omega_z", "v_z"]
    assert got["v_z"] == pytest.approx(-1.5, abs=1e-9)


def test_resolve_a_folder_a_file_and_a_run(state_file, tmp_path):
    from jt_tasks.takeoff import source
    from toolkit.store.tracking import Store

    assert source.resolve(str(state_file.parent), None) == state_file.resolve()
    assert source.resolve(str(state_file), None) == state_file.resolve()
    store = Store(tmp_path)
    single = store.start_run("runup")  # search=single: the file is the run's own artifact
    store.log_artifact(single, state_file)
    store.end_run(single)
    assert source.resolve(single, str(tmp_path)) == store.artifact_dir(single) / "takeoff_state.h5"


@pytest.mark.parametrize("ref, message", [("0" * 32, "no such run"), ("/no/where", "no takeoff_state.h5 there")])
def test_resolve_errors_are_one_line_and_create_no_store(ref, message, tmp_path):
    from jt_tasks.takeoff import source
    from toolkit.errors import JtError

    with pytest.raises(JtError, match=message) as e:
        source.resolve(ref, str(tmp_path / "store"))
    assert "\n" not in str(e.value) and "task.takeoff_from=" in str(e.value)
    assert not (tmp_path / "store").exists()


def test_a_run_without_the_file_says_so(tmp_path):
    from jt_tasks.takeoff import source
    from toolkit.errors import JtError
    from toolkit.store.tracking import Store

    store = Store(tmp_path)
    rid = store.start_run("highjump")
    store.end_run(rid)
    with pytest.raises(JtError, match=r"no take-off state \(no takeoff_state.h5 artifact\); is it a task=runup run"):
        source.resolve(rid, str(tmp_path))


@pytest.mark.parametrize("content, message", [
    (b"garbage, not HDF5", "not a readable HDF5 file"),
    (None, "not a take-off state \\(no q, qd, time, foot, features\\)"),
    ({"q": np.zeros(3), "qd": np.zeros(3), "time": 0.0, "foot": "right", "features": {}}, "malformed"),
    ({"q": np.full(43, np.nan), "qd": np.zeros(34), "time": 0.0, "foot": "right", "features": {}}, "malformed"),
])
def test_a_bad_takeoff_file_is_one_line_error_before_a_run_opens(content, message, tmp_path):
    from toolkit.config import compose
    from toolkit.errors import JtError
    from toolkit.execution.runner import run
    from toolkit.store import h5

    path = tmp_path / "takeoff_state.h5"
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        h5.write(path, content or {"other": np.zeros(2)})
    store = tmp_path / "store"
    with pytest.raises(JtError, match=message) as e:
        run(compose(["task=highjump", "experiment=smoke", f"task.takeoff_from={path}", f"store={store}"]))
    assert "\n" not in str(e.value)
    assert not (store / "runs").exists()  # no run was opened
