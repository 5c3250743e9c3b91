"""A task's declared ``record_keys`` (what composition checks reward terms against, issue 30) are
exactly the keys its environment gives the reward terms: measured on a real environment, so a key
added to or dropped from the record without its declaration fails here."""

from __future__ import annotations

import numpy as np
import pytest

from toolkit import plugins
from toolkit.config import compose


def _env(task: str, tmp_path):
    cfg = compose([f"task={task}", "experiment=smoke", "action=raw", f"store={tmp_path / 'store'}"])
    env = plugins.load("task", task)(cfg).make_env(seed=0)
    env.reset(seed=0)
    env.step(np.zeros(env.action_space.shape, np.float32))
    return env


@pytest.mark.parametrize("task", ["highjump", "obstacle"])
def test_a_jumps_episode_record_has_exactly_its_declared_keys(task, tmp_path):
    env = _env(task, tmp_path)
    try:
        assert set(env.episode_record(False)) == set(plugins.load("task", task).record_keys)
    finally:
        env.close()


def test_the_get_ups_step_record_has_exactly_its_declared_keys(tmp_path):
    env = _env("getup", tmp_path)
    try:
        assert set(env.record_now()) == set(plugins.load("task", "getup").record_keys)
    finally:
        env.close()
