"""``toolkit.store.resolve``: run ids (own artifact, nested evaluation, best of the nested runs, an
evaluation index), folders and files, in a real MLflow store with real HDF5 artifacts."""

from __future__ import annotations

from pathlib import Path

import pytest

from toolkit.errors import JtError
from toolkit.store.resolve import open_store, resolve, search_runs

NAME = "thing.h5"


def _h5(path: Path, value: float = 1.0) -> Path:
    from toolkit.store import h5

    path.parent.mkdir(parents=True, exist_ok=True)
    return h5.write(path, {"x": value}, {"format": "jt.test/1"})


@pytest.fixture
def store(tmp_path):
    """``(root, Store, runs)``: a single run, an outer run with three evaluations, an empty run."""
    from toolkit.store.tracking import Store

    root = tmp_path / "store"
    st = Store(root)
    src = tmp_path / "src"
    runs = {"single": st.start_run("exp")}
    st.log_artifact(runs["single"], _h5(src / "single" / NAME))
    runs["outer"] = st.start_run("exp")
    for i, (score, has) in enumerate(((0.5, True), (0.9, True), (2.0, False), (0.9, True))):
        kid = st.start_run("exp", parent_run_id=runs["outer"], tags={"jt.eval_index": str(i)})
        if has:  # evaluation 2 scores best but holds no artifact
            st.log_artifact(kid, _h5(src / f"kid{i}" / NAME, i))
        with st.metrics(kid) as buf:
            buf.add("score", score)
        st.end_run(kid)
        runs[f"kid{i}"] = kid
    st.end_run(runs["outer"])
    runs["empty"] = st.start_run("exp")
    st.end_run(runs["empty"])
    return root, st, runs


def _one_line(excinfo, *parts):
    msg = str(excinfo.value)
    assert "\n" not in msg, msg
    for p in parts:
        assert p in msg, msg
    return msg


def test_a_run_with_its_own_artifact(store):
    root, st, runs = store
    got = resolve(runs["single"], artifact=NAME, store=str(root))
    assert got.path == st.artifact_dir(runs["single"]) / NAME and got.path.is_file()
    assert got.run_id == runs["single"] and got.run.info.run_id == runs["single"]
    assert got.eval_index == -1 and got.folder == got.path.parent


def test_a_nested_evaluation_is_itself(store):
    root, st, runs = store
    got = resolve(runs["kid3"], artifact=NAME, store=str(root), best_by=["score"])
    assert (got.run_id, got.eval_index) == (runs["kid3"], 3)
    with pytest.raises(JtError) as e:
        resolve(runs["kid2"], artifact=NAME, store=str(root), what="task.init", hint="do this")
    _one_line(e, f"task.init={runs['kid2']}", f"no {NAME} artifact", "; do this")


def test_an_outer_run_gives_the_best_nested_run_holding_the_artifact(store):
    root, st, runs = store
    by_metric = resolve(runs["outer"], artifact=NAME, store=str(root), best_by=["score"])
    assert (by_metric.run_id, by_metric.eval_index) == (runs["kid1"], 1)  # 0.9 ties with 3: lower index
    assert by_metric.path == st.artifact_dir(runs["kid1"]) / NAME
    by_fn = resolve(runs["outer"], artifact=NAME, store=str(root), best_by=lambda r: -r.data.metrics["score"])
    assert by_fn.eval_index == 0
    assert resolve(runs["outer"], artifact=NAME, store=str(root)).eval_index == 0  # no best_by: lowest index
    assert resolve(runs["outer"], artifact=NAME, store=str(root), eval_index=3).run_id == runs["kid3"]


@pytest.mark.parametrize("index, message", [(7, "has evaluations [0, 1, 2, 3]"), (2, "has no trained policy")])
def test_bad_evaluation_index(store, index, message):
    root, _, runs = store
    with pytest.raises(JtError) as e:
        resolve(runs["outer"], artifact=NAME, store=str(root), eval_index=index, label="trained policy",
                index_what="task.init_eval")
    _one_line(e, message)
    with pytest.raises(JtError) as e:
        resolve(runs["single"], artifact=NAME, store=str(root), eval_index=0, index_what="task.init_eval")
    _one_line(e, "task.init_eval=0", "no nested evaluations")


def test_a_run_without_the_artifact(store):
    root, _, runs = store
    with pytest.raises(JtError) as e:
        resolve(runs["empty"], artifact=NAME, store=str(root), what="task.takeoff_from", label="take-off state",
                hint="is it a task=runup run?")
    _one_line(e, f"task.takeoff_from={runs['empty']}: run {runs['empty']} has no take-off state (no {NAME} artifact)",
              "is it a task=runup run?")
    with pytest.raises(JtError) as e:
        resolve(runs["outer"], artifact="other.h5", store=str(root))
    _one_line(e, "no other.h5 artifact, nor has any of its 4 nested runs")


def test_folder_and_file(tmp_path):
    direct = _h5(tmp_path / "a" / NAME)
    below = _h5(tmp_path / "b" / "eval" / NAME)
    _h5(tmp_path / "c" / "x" / "y" / NAME)  # two folders down: not looked at
    assert resolve(str(tmp_path / "a"), artifact=NAME).path == direct.resolve()
    got = resolve(str(tmp_path / "b"), artifact=NAME)
    assert got.path == below.resolve() and got.run is None and got.run_id == "" and got.eval_index == -1
    assert got.folder == below.parent.resolve()
    other = _h5(tmp_path / "a" / "other.h5")
    assert resolve(str(other), artifact=NAME).path == other.resolve()  # a file is taken as it is
    with pytest.raises(JtError) as e:
        resolve(str(tmp_path / "c"), artifact=NAME, what="action.prior", hint="make one")
    _one_line(e, f"action.prior={tmp_path / 'c'}: no {NAME} there", "; make one")
    with pytest.raises(JtError) as e:
        resolve(str(tmp_path / "nope.h5"), artifact=NAME)
    _one_line(e, "no such file")


def test_accept_takes_other_names_but_never_looks_deeper_than_one_folder(tmp_path):
    seen = []

    def accept(p):
        seen.append(p)
        return p.name.startswith("ok")

    _h5(tmp_path / "sub" / "ok_1.h5")
    _h5(tmp_path / "no.h5")
    _h5(tmp_path / "sub" / "deeper" / "ok_0.h5")
    assert resolve(str(tmp_path), artifact=NAME, accept=accept).path.name == "ok_1.h5"
    assert all(len(p.relative_to(tmp_path).parts) <= 2 for p in seen)


def test_an_unknown_run_id_creates_no_store(tmp_path):
    root = tmp_path / "nowhere"
    with pytest.raises(JtError) as e:
        resolve("0" * 32, artifact=NAME, store=str(root), what="task.init", hint="give a run id")
    _one_line(e, "task.init=" + "0" * 32, "no such run", str(root), "give a run id")
    assert not root.exists() and open_store(str(root)) is None


def test_an_unknown_run_id_in_a_store(store):
    root, _, _ = store
    with pytest.raises(JtError) as e:
        resolve("f" * 32, artifact=NAME, store=str(root))
    _one_line(e, "no such run in store", str(root))
    with pytest.raises(JtError) as e:
        resolve("", artifact=NAME, store=str(root))
    _one_line(e, "empty")


def test_search_runs_by_tags_params_and_status(store):
    root, st, runs = store
    st.log_params(runs["single"], {"task.stage": 2})
    exp = [st.experiment_id("exp")]
    assert [r.info.run_id for r in search_runs(st, exp, params={"task.stage": 2}, status="FINISHED")] == []
    st.end_run(runs["single"])
    assert [r.info.run_id for r in search_runs(st, exp, params={"task.stage": "2"}, status="FINISHED")] == \
        [runs["single"]]
    kids = search_runs(st, exp, tags={"mlflow.parentRunId": runs["outer"], "jt.eval_index": "2"})
    assert [r.info.run_id for r in kids] == [runs["kid2"]]
    with pytest.raises(JtError):
        search_runs(st, exp, tags={"mlflow.parentRunId": "x' or '1' = '1"})


def test_run_config_is_the_one_beside_the_artifact_or_one_folder_up(tmp_path):
    from toolkit.store.resolve import run_config

    (tmp_path / "eval_0000").mkdir()
    art = tmp_path / "eval_0000" / "ppo.h5"
    art.write_bytes(b"")
    with pytest.raises(JtError, match=r"no config.yaml beside .*ppo.h5 \(the run's work folder\); pass --config"):
        run_config(art)
    (tmp_path / "config.yaml").write_text("a: 1\n")
    assert run_config(art) == tmp_path / "config.yaml"
    (tmp_path / "eval_0000" / "config.yaml").write_text("a: 2\n")
    assert run_config(art) == tmp_path / "eval_0000" / "config.yaml"  # the nearer one
    with pytest.raises(JtError, match=r"--config=.*nope.yaml: no such file"):
        run_config(art, str(tmp_path / "nope.yaml"))
    assert run_config(art, str(tmp_path / "config.yaml")) == tmp_path / "config.yaml"
