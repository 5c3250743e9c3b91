"""action.prior=auto: the store's own prior, trained once and then reused (toolkit.priors.auto)."""

from __future__ import annotations

import pytest

from toolkit.errors import JtError


def _cfg(store, *extra, run_checks=True):
    from toolkit.config import compose

    return compose(["task=highjump", "search=single", "experiment=smoke", "action=pvae", f"store={store}", *extra],
                   run_checks=run_checks)


def _train_prior(store, overrides, tag):
    from toolkit.execution.runner import _train_prior as train

    return train(store, overrides, tag)


def test_the_prior_to_train_is_the_action_spaces_own_declaration():
    """The core names no prior kind: the action space's ``prior_run`` hook says what to train
    (pvae / cvae: ``task=pose_prior action=<kind>``); other spaces and the training run itself
    ask for nothing."""
    from toolkit.config import compose
    from toolkit.priors import auto

    cfg = compose(["task=highjump", "action=pvae"])
    assert auto.prior_run(cfg) == ["task=pose_prior", "action=pvae"]
    assert auto.prior_run(compose(["task=getup"])) == ["task=pose_prior", "action=cvae"]
    assert auto.prior_run(compose(["task=highjump", "action=raw"])) == []
    assert auto.prior_run(compose(["task=pose_prior", "action=pvae"])) == []  # the training run itself


def test_auto_trains_once_then_reuses(tmp_path):
    from toolkit.priors import auto
    from toolkit.priors.io import load_prior
    from toolkit.store.tracking import Store

    cfg = _cfg(tmp_path)
    assert str(cfg.action.prior) == "auto" and auto.wants_auto(cfg) == "pvae"
    first = auto.resolve(cfg, _train_prior)  # a smoke run trains a smoke-sized prior
    run_id = str(first.action.prior)
    assert run_id != "auto" and load_prior(run_id, str(tmp_path), kind="pvae").latent_dim > 0
    store = Store(tmp_path)
    assert store.get_run(run_id).data.tags[auto.TAG] == "pvae@smoke"
    assert store.get_run(run_id).data.params["task.epochs"] == "3"  # experiment=smoke of task=pose_prior
    again = auto.resolve(_cfg(tmp_path), _train_prior)
    assert str(again.action.prior) == run_id  # reused, not trained again
    exp = store.client.get_experiment_by_name("pose_prior")
    assert len(store.client.search_runs([exp.experiment_id])) == 1
    assert auto.find(store, "pvae", "pose_prior") == ""  # a smoke prior is never taken for a full-size run


def test_explicit_priors_and_raw_actions_are_left_alone(tmp_path):
    from toolkit.priors import auto

    cfg = _cfg(tmp_path, "action=raw")
    assert auto.wants_auto(cfg) == "" and auto.resolve(cfg, _train_prior) is cfg
    given = tmp_path / "somewhere" / "prior.h5"  # read at composition: tests/plugins/jt_tasks/getup/test_getup_cvae.py
    given.parent.mkdir()
    given.write_bytes(b"")
    cfg = _cfg(tmp_path, f"action.prior={given}", run_checks=False)
    assert auto.wants_auto(cfg) == "" and str(auto.resolve(cfg, _train_prior).action.prior) == str(given)
    assert not (tmp_path / "mlflow.db").exists()  # nothing was looked up or trained


def test_auto_outside_jt_run_is_one_line_error():
    from toolkit.priors.io import load_prior

    with pytest.raises(JtError, match="resolved by jt run") as e:
        load_prior("auto", kind="pvae")
    assert "\n" not in str(e.value)
