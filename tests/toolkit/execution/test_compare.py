"""jt compare: a grid over seeds becomes one table, one HDF5, one PNG and a comparison run."""

import numpy as np

from toolkit.execution.compare import compare, compare_runs, parse_vary
from toolkit.store import h5


def test_grid_table_and_comparison_run(example_plugin, store_dir):
    res = compare(["task=quadratic", "executor.workers=1", f"store={store_dir}"],
                  ["task.centre=0.0,0.5"], seeds=2)
    assert [r["variant"] for r in res.rows] == ["task.centre=0.0", "task.centre=0.5"]
    assert all(r["n"] == 2 for r in res.rows)
    # the default point is (0, 0): value = 2 * centre^2 exactly, with no spread over seeds
    assert np.isclose(res.rows[0]["value"][0], 0.0) and np.isclose(res.rows[1]["value"][0], 0.5)
    assert "value" in res.table.splitlines()[0] and "0.5 ± 0" in res.table
    from toolkit.store.tracking import Store

    store = Store(store_dir)
    art = store.artifact_dir(res.run_id)
    table = h5.read(art / "compare.h5")
    np.testing.assert_allclose(table["mean"]["value"], [0.0, 0.5])
    assert (art / "compare.png").stat().st_size > 1000
    tags = store.get_run(res.run_id).data.tags
    child_ids = tags["jt.compare.runs"].split(",")
    assert len(child_ids) == 4
    assert all(store.get_run(c).data.tags["mlflow.parentRunId"] == res.run_id for c in child_ids)
    again = compare_runs(child_ids, [f"store={store_dir}"])
    assert [r["variant"] for r in again.rows] == ["task.centre=0.0", "task.centre=0.5"]


def test_parse_vary_rejects_bad_syntax():
    import pytest

    from toolkit.errors import JtError

    assert parse_vary(["a=1,2", "b=x"]) == [("a", ["1", "2"]), ("b", ["x"])]
    with pytest.raises(JtError):
        parse_vary(["nokey"])


def test_varying_the_seed_runs_what_the_row_says(example_plugin, store_dir):
    """``--vary seed=5,6``: each row's runs have that seed (compare's own seed offset used to win)."""
    from toolkit.store.tracking import Store

    res = compare(["task=quadratic", "executor.workers=1", "seed=3", f"store={store_dir}"], ["seed=5,6"], seeds=2)
    assert [r["variant"] for r in res.rows] == ["seed=5", "seed=6"]
    store = Store(store_dir)
    kids = store.get_run(res.run_id).data.tags["jt.compare.runs"].split(",")
    seeds = [int(store.get_run(k).data.params["seed"]) for k in kids]
    assert seeds == [5, 6, 6, 7]


def test_vary_with_no_or_repeated_values_is_one_line():
    import pytest

    from toolkit.errors import JtError

    for bad in (["seed=,"], ["spd=df,df"]):
        with pytest.raises(JtError, match="bad --vary"):
            parse_vary(bad)


def test_runs_are_named_for_what_they_are_and_never_collide(example_plugin, store_dir):
    """Outer runs ``<task>·<search>·seed<N>`` (a second one ``...·2``); compare children
    ``<variant>·seed=<N>``: MLflow's own names come from the global random that jt seeds."""
    from toolkit.config import compose
    from toolkit.execution.runner import run
    from toolkit.store.tracking import Store

    a = run(compose(["task=quadratic", "executor.workers=1", f"store={store_dir}"]))
    b = run(compose(["task=quadratic", "executor.workers=1", f"store={store_dir}"]))
    store = Store(store_dir)
    assert store.get_run(a.run_id).info.run_name == "quadratic·single·seed0"
    assert store.get_run(b.run_id).info.run_name == "quadratic·single·seed0·2"
    res = compare(["task=quadratic", "executor.workers=1", f"store={store_dir}"], ["task.centre=0.0,0.5"], seeds=1)
    kids = store.get_run(res.run_id).data.tags["jt.compare.runs"].split(",")
    names = [store.get_run(k).data.tags["mlflow.runName"] for k in kids]
    assert names == ["task.centre=0.0·seed=0", "task.centre=0.5·seed=0"]


def test_the_comparison_run_reads_well(example_plugin, store_dir):
    """Params (base overrides, varied keys, seeds), MLflow's commit and user tags, one metric per
    variant and statistic, the table as its markdown description; children rerun on their own."""
    from toolkit.store.tracking import Store

    res = compare(["task=quadratic", "executor.workers=1", f"store={store_dir}"], ["task.centre=0.0,0.5"], seeds=2)
    run = Store(store_dir).get_run(res.run_id)
    p, m, tags = run.data.params, run.data.metrics, run.data.tags
    assert p["base.task"] == "quadratic" and p["vary.task.centre"] == "0.0,0.5" and p["seeds"] == "2"
    assert tags["mlflow.source.git.commit"] and tags["mlflow.user"] and tags["jt.command"].startswith("jt compare")
    assert m["0.5/value_mean"] == 0.5 and m["0.5/value_std"] == 0.0 and m["0.0/value_mean"] == 0.0
    assert m["0.5/n"] == 2
    store = Store(store_dir)
    assert [h.step for h in store.client.get_metric_history(res.run_id, "0.5/value_mean")] == [0]
    assert "value_mean" not in m  # no single key over steps mixing the variants
    note = tags["mlflow.note.content"]
    # a row per metric, a column per variant (readable in the UI's narrow description pane)
    assert "| metric | task.centre=0.0 | task.centre=0.5 |" in note and "| value | 0 ± 0 | 0.5 ± 0 |" in note
    assert "| seeds (n) | 2 | 2 |" in note
    assert "task.centre=0.5·seed=1" in note  # the children by name
    kid = store.get_run(tags["jt.compare.runs"].split(",")[-1])
    assert kid.data.tags["jt.command"] == f"jt run task=quadratic executor.workers=1 store={store_dir} " \
                                         "task.centre=0.5 seed=1"


def test_hydra_prefixed_overrides_are_params_mlflow_takes(example_plugin, store_dir):
    """``~group`` and ``+key=v`` are legal overrides but not legal MLflow keys: the comparison's
    params name them without the prefix (``~curriculum`` used to end as an internal error with
    the comparison run left RUNNING)."""
    from toolkit.execution.compare import _params
    from toolkit.store.tracking import Store

    assert _params(["~curriculum", "+a.b=1", "++c=2", "seed=3"], [("x", ["1", "2"])], 2) == {
        "base.curriculum": "~", "base.a.b": "1", "base.c": "2", "base.seed": "3", "vary.x": "1,2", "seeds": "2"}
    res = compare(["task=quadratic", "~curriculum", "executor.workers=1", f"store={store_dir}"],
                  ["task.centre=0.0,0.5"], seeds=1)
    run = Store(store_dir).get_run(res.run_id)
    assert run.info.status == "FINISHED" and run.data.params["base.curriculum"] == "~"


def test_curves_of_the_compared_runs_are_drawn_per_variant(example_plugin, store_dir):
    """Key metrics the runs logged as curves (the example task's ``train/curve``, 5 points each)
    get ``compare_curves.png``: each variant's runs and their mean at the shared steps."""
    from toolkit.execution.compare import _curves, _plot_curves
    from toolkit.store.tracking import Store

    res = compare(["task=quadratic", "executor.workers=1", f"store={store_dir}"], ["task.centre=0.0,0.5"], seeds=2)
    store = Store(store_dir)
    kids = store.get_run(res.run_id).data.tags["jt.compare.runs"].split(",")
    per_cell = [(r["variant"], rid, {}) for r in res.rows for rid in r["runs"]]
    curves = _curves(store, per_cell, ["train/curve", "value"])
    assert list(curves) == ["train/curve"]  # value is one number per run, not a curve
    assert {v: len(runs) for v, runs in curves["train/curve"].items()} == {"task.centre=0.0": 2, "task.centre=0.5": 2}
    assert all(r.shape == (5, 2) and list(r[:, 0]) == [0, 1, 2, 3, 4] for runs in curves["train/curve"].values() for r in runs)
    assert len(kids) == 4
    png = store_dir / "curves.png"
    assert _plot_curves(curves, png, "centre") == ["train/curve"] and png.stat().st_size > 5000
    assert _plot_curves({}, store_dir / "none.png", "") == [] and not (store_dir / "none.png").exists()
    # the quadratic task's key metric (value) has no curve: its comparison draws none
    assert not (store.artifact_dir(res.run_id) / "compare_curves.png").exists()


def test_runs_are_told_apart_by_the_params_they_set():
    """A group whose name differs shows as ``group=name``; a key one group lacks (``raw`` has no
    prior) tells runs apart only where it is set and differs."""
    from toolkit.execution.compare import differing_params, variant_label

    cvae = {"action.name": "cvae", "action.beta": "0.2", "action.prior": "abc", "seed": "0", "task.name": "getup"}
    nofilter = {**cvae, "action.beta": "1.0", "seed": "1"}
    raw = {"action.name": "raw", "action.around_start": "False", "seed": "0", "task.name": "getup"}
    diff = differing_params([cvae, nofilter, raw])
    assert diff == ["action.name", "action.beta"]
    assert [variant_label(p, diff) for p in (cvae, nofilter, raw)] == [
        "action=cvae, action.beta=0.2", "action=cvae, action.beta=1.0", "action=raw"]
    assert differing_params([cvae, {**cvae, "seed": "5"}]) == []


def test_a_cell_its_plugins_refuse_is_one_line_before_any_cell_runs(tmp_path):
    """``--vary search=random,bds`` on a task BDS cannot search: the random cell used to run all
    60 evaluations and then the compare run was left FAILED; now nothing is run or written."""
    import pytest

    from toolkit.errors import JtError

    store = tmp_path / "s"
    with pytest.raises(JtError) as e:
        compare(["task=zdt1", "experiment=smoke", f"store={store}"], ["search=random,bds"], 1)
    assert "search=bds" in str(e.value) and "n_features" in str(e.value) and "\n" not in str(e.value)
    assert not store.exists()


def test_vary_keeps_list_dict_and_quoted_values_whole():
    import pytest

    from toolkit.errors import JtError

    assert parse_vary(["task.rates_hz=[30,60],[600]"]) == [("task.rates_hz", ["[30,60]", "[600]"])]
    assert parse_vary(["x={a: 1, b: 2},{a: 3}"]) == [("x", ["{a: 1, b: 2}", "{a: 3}"])]
    assert parse_vary(["x='a,b',c"]) == [("x", ["'a,b'", "c"])]
    for bad in ("x=[1,2", "x=1],2", "x='a,b"):
        with pytest.raises(JtError, match="bad --vary"):
            parse_vary([bad])
