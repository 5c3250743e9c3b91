"""The evaluation every few PPO iterations (toolkit.policy.periodic): when it runs, where its rows
live, how a resumed run continues them, what the task's own hook and the progress line get; one
evaluation runs real episodes of the minimal policy task (stand_example.py)."""

from __future__ import annotations

import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from toolkit.policy.periodic import KEY, PeriodicEvaluation  # noqa: E402

MODEL = object()


def stats(model=MODEL) -> SimpleNamespace:
    return SimpleNamespace(model=model, episodes=[])


def test_every_nth_iteration_appends_a_row_and_the_task_hook_runs_each_time():
    extra: dict = {}
    seen, said = [], []
    calls = []

    def evaluate(model):
        assert model is MODEL
        calls.append(len(calls))
        return [float(len(calls)), 0.5]

    def then(it, samples, st):
        seen.append(it)
        return {"difficulty": it}

    hook = PeriodicEvaluation(extra, ("score", "share"), 2, evaluate, then, lambda f, m: said.append((f, m)),
                              total=400, message=lambda v: f"score {v[0]:.0f}")
    assert extra[KEY].shape == (0, 3)  # there from the start: every checkpoint has the entry
    outs = [hook(it, 100 * it, stats()) for it in range(1, 6)]
    assert seen == [1, 2, 3, 4, 5] and outs == [{"difficulty": it} for it in range(1, 6)]
    np.testing.assert_array_equal(hook.history(), [[200, 1, 0.5], [400, 2, 0.5]])
    assert said == [(0.5, "score 1"), (1.0, "score 2")]
    assert hook.curves() == {"score": [(200, 1.0), (400, 2.0)], "share": [(200, 0.5), (400, 0.5)]}
    assert hook.curves({"score": "eval_score"}) == {"eval_score": [(200, 1.0), (400, 2.0)]}


def test_a_resumed_run_continues_the_rows_in_extra():
    extra: dict = {}
    PeriodicEvaluation(extra, ("v",), 1, lambda m: [1.0])(1, 64, stats())
    saved = {KEY: np.array(extra[KEY])}  # what ppo.h5 gives back on resume
    again = PeriodicEvaluation(saved, ("v",), 1, lambda m: [2.0])
    assert again.history().tolist() == [[64.0, 1.0]]
    again(2, 128, stats())
    assert again.history().tolist() == [[64.0, 1.0], [128.0, 2.0]]


def test_nothing_is_evaluated_without_a_model_or_with_every_zero():
    def never(model):
        raise AssertionError("evaluated")

    for every, st in ((0, stats()), (1, stats(None)), (3, stats())):
        hook = PeriodicEvaluation({}, ("v",), every, never)
        assert hook(1, 10, st) == {}  # no task hook: nothing for the envs
        assert hook.history().shape == (0, 2)


def test_an_evaluation_gives_one_value_per_column_and_a_subclass_may_evaluate():
    with pytest.raises(ValueError, match="2 values for the columns v"):
        PeriodicEvaluation({}, ("v",), 1, lambda m: [1.0, 2.0])(1, 10, stats())
    with pytest.raises(NotImplementedError):
        PeriodicEvaluation({}, ("v",), 1)(1, 10, stats())

    class Own(PeriodicEvaluation):
        def evaluate(self, model):
            return (7.0,)

    hook = Own({}, ("v",), 1, key="own_history")
    hook(1, 10, stats())
    assert hook.extra["own_history"].tolist() == [[10.0, 7.0]] and KEY not in hook.extra


def test_an_evaluation_of_real_episodes_keeps_what_they_gave():
    from omegaconf import OmegaConf
    from stand_example import StandTask

    from toolkit.config import compose
    from toolkit.policy.episodes import opened_env, rollout

    cfg = compose(["task=runup", "experiment=smoke"])
    OmegaConf.set_struct(cfg, False)
    cfg.task = {"name": "stand", "time_limit": 0.2}
    task = StandTask(cfg)

    class Zero:
        def act(self, obs):
            return np.zeros(n)

    def lasted(model):  # control steps and return of one deterministic episode
        with opened_env(task.make_env, seed=0) as env:
            ro = rollout(env, model)
        return [ro.steps, ro.return_]

    with opened_env(task.make_env, seed=0) as env:
        n = env.action_space.shape[0]
        direct = rollout(env, Zero())
    hook = PeriodicEvaluation({}, ("steps", "return"), 1, lasted)
    hook(1, 32, stats(Zero()))
    assert hook.history().tolist() == [[32.0, float(direct.steps), float(direct.return_)]]
    assert direct.steps >= 1
