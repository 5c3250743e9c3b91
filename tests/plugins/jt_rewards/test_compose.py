"""compose.product: the reward is the product of its terms, each value kept (000 eqs 2, 15, 16)."""

from __future__ import annotations

import math

import pytest

from jt_rewards.compose import product
from jt_rewards.novelty import Novelty
from jt_rewards.terms import Naturalness, RootRotation, Safety, TaskComplete

RECORD = {"success": True, "root_ang_vel_mean": 5.0, "head_first_landing": True, "naturalness": 0.75,
          "feature": [0.0, 0.0, 0.5], "policy_features": [[0.0, 0.0, 0.0]]}


def terms():
    return {"task_complete": TaskComplete(), "root_rotation": RootRotation(), "safety": Safety(),
            "naturalness": Naturalness(), "novelty": Novelty()}


def test_product_is_the_product_of_the_terms():
    total, values = product(terms(), RECORD)
    expected = {"task_complete": 1.0, "root_rotation": math.exp(-0.1), "safety": 0.7,
                "naturalness": 0.75, "novelty": 0.5 / (math.pi / 2)}
    assert values == pytest.approx(expected, rel=1e-12)
    assert total == pytest.approx(math.prod(expected.values()), rel=1e-12)
    assert list(values) == list(expected)  # in the configured order


def test_failed_episode_is_zero_but_every_term_is_still_logged():
    total, values = product(terms(), dict(RECORD, success=False))
    assert total == 0.0 and values["task_complete"] == 0.0
    assert values["safety"] == 0.7 and len(values) == 5


def test_list_of_terms_named_by_class_and_empty_set():
    total, values = product([TaskComplete(), Safety()], RECORD)
    # each term by its own name: the registry's once loaded through it, else the class's
    assert values == {TaskComplete().term_name: 1.0, Safety().term_name: 0.7} and total == 0.7
    assert TaskComplete().term_name in ("TaskComplete", "task_complete")
    assert product([], RECORD) == (1.0, {})
    with pytest.raises(ValueError, match="distinct"):
        product([Safety(), Safety({"factor": 0.5})], RECORD)


def test_plain_callables_compose_too():
    total, values = product({"half": lambda r: 0.5, "success": lambda r: float(r["success"])}, RECORD)
    assert total == 0.5 and values == {"half": 0.5, "success": 1.0}
