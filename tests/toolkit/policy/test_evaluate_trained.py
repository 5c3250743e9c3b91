"""``task.evaluate=RUN``: a trained policy measured again without training (the policy layer)."""

from __future__ import annotations

import pytest

from toolkit.errors import JtError


def _run(tmp_path, *extra):
    from toolkit.config import compose
    from toolkit.execution.runner import run

    return run(compose(["task=runup", "experiment=smoke", f"store={tmp_path}", *extra]))


def _metrics(res):
    return res.store.client.get_run(res.run_id).data.metrics


def test_evaluating_a_trained_run_collects_nothing_and_measures_the_same(tmp_path):
    trained = _run(tmp_path)
    again = _run(tmp_path, f"task.evaluate={trained.run_id}")
    m0, m1 = _metrics(trained), _metrics(again)
    assert m1["samples"] == m0["samples"] and m1["iterations"] == m0["iterations"]
    for key in ("mean_return", "imitation_reward", "goal_reward", "episode_time"):
        assert m1[key] == pytest.approx(m0[key], abs=1e-9), key
    # the folder holding ppo.h5 works the same as the run id
    folder = trained.store.artifact_dir(trained.run_id)
    assert _metrics(_run(tmp_path, f"task.evaluate={folder}"))["mean_return"] == pytest.approx(m0["mean_return"])


def test_a_missing_trained_run_is_one_line_before_a_run_opens(tmp_path):
    from toolkit.config import compose

    with pytest.raises(JtError, match=r"task.evaluate=nope: .*train one with: jt run task=runup"):
        compose(["task=runup", "experiment=smoke", f"store={tmp_path}", "task.evaluate=nope"])
    assert not (tmp_path / "mlflow.db").exists()


def test_a_policy_of_another_task_is_one_line_before_a_run_opens(tmp_path):
    """A run-up policy (125 observations) named by task.evaluate for the spacetime walk: refused at
    composition with both sizes, where it used to fail mid-run on a state_dict size mismatch."""
    from toolkit.config import compose

    trained = _run(tmp_path)
    client = trained.store.client

    def n_runs():
        return len(client.search_runs([e.experiment_id for e in client.search_experiments()]))

    before = n_runs()
    with pytest.raises(JtError, match=r"task.evaluate=\w+: its policy takes 125 observations and gives 28 actions; "
                                      r"task=spacetime as configured here observes 148"):
        compose(["task=spacetime", "experiment=smoke", "action=raw", f"store={tmp_path}",
                 f"task.evaluate={trained.run_id}"])
    assert n_runs() == before  # no spacetime run row, not even a failed one


def test_a_trained_policy_with_the_stores_own_prior_composes(tmp_path):
    """``task.evaluate`` beside ``action.prior=auto`` (every ``experiment=laptop`` of a prior-based
    task): the policy's fit is checked once the runner has found the prior, not at composition,
    which refused it ("action.prior=auto is resolved by jt run")."""
    from toolkit.config import compose

    trained = _run(tmp_path)
    cfg = compose(["task=runup", "experiment=smoke", f"store={tmp_path}", "action=pvae", "action.prior=auto",
                   f"task.evaluate={trained.run_id}"])
    assert str(cfg.action.prior) == "auto"


def test_a_policy_that_does_not_fit_the_stores_own_prior_is_one_line_before_the_run_opens(tmp_path):
    """With ``action.prior=auto`` the fit is checked once the runner has found (here: trained) the
    prior, still before the run opens: a raw-action policy (28 actions) for P-VAE actions is one
    ``JtError`` line and no run-up run row, not a FAILED run."""
    from toolkit.config import compose
    from toolkit.execution.runner import run

    trained = _run(tmp_path)
    client = trained.store.client
    exp = client.get_experiment_by_name("runup")

    def runup_runs():
        return len(client.search_runs([exp.experiment_id]))

    before = runup_runs()
    with pytest.raises(JtError, match=r"task.evaluate=\w+: its policy takes \d+ observations and gives 28 actions"):
        run(compose(["task=runup", "experiment=smoke", f"store={tmp_path}", "action=pvae", "action.prior=auto",
                     f"task.evaluate={trained.run_id}"]))
    assert runup_runs() == before
