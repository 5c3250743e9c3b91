"""The contract every jt reward term meets; each term's test module subclasses it.

A subclass sets ``cls`` (the term class), ``entry`` (its registry name), ``record`` (a complete,
valid record), ``required`` (the record keys the term needs with its default config) and ``cases``
(``(params, record, expected)`` triples, hand-computed)::

    from toolkit.testing.reward import RewardTermContract

    class TestUpright(RewardTermContract):
        cls, entry = Upright, "upright"
        record, required = {"up": 1.0}, ("up",)
        cases = [({}, {"up": 0.5}, 0.5)]
"""

from __future__ import annotations

import copy
import dataclasses
import math
from importlib import metadata
from typing import Any, ClassVar

import pytest
from omegaconf import OmegaConf

from toolkit.errors import JtError
from toolkit.interfaces.reward import RewardTerm


class RewardTermContract:
    """Config dataclass with defaults, summary, factor in [0, 1], pure, hand-computed cases."""

    cls: ClassVar[type]
    entry: ClassVar[str]
    record: ClassVar[dict[str, Any]]
    required: ClassVar[tuple[str, ...]]
    cases: ClassVar[list[tuple[dict, dict, float]]]

    def test_is_a_reward_term_with_a_config(self):
        term = self.cls()
        assert isinstance(term, RewardTerm) and self.cls.summary()
        assert dataclasses.is_dataclass(self.cls.Config) and isinstance(term.params, self.cls.Config)
        for f in dataclasses.fields(self.cls.Config):  # every YAML key has a default
            assert f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING

    def test_config_from_none_dict_node_and_instance_agree(self):
        base = self.cls().params
        assert self.cls({}).params == base
        assert self.cls(OmegaConf.create({})).params == base
        assert self.cls(base).params == base
        assert self.cls(dataclasses.asdict(base)).params == base

    def test_unknown_key_is_one_clear_error(self):
        with pytest.raises(JtError, match="unknown key.*valid keys"):
            self.cls({"no_such_key": 1})

    def test_value_is_a_factor_in_unit_interval(self):
        v = self.cls()(dict(self.record))
        assert isinstance(v, float) and 0.0 <= v <= 1.0

    def test_pure_function_of_the_record(self):
        term = self.cls()
        rec = copy.deepcopy(self.record)
        a, b = term(rec), term(rec)
        assert a == b
        assert repr(rec) == repr(self.record)  # the record is not modified

    def test_declares_the_record_keys_it_reads(self):
        """``RewardTerm.needs`` (checked against a task's ``record_keys`` at composition) names the
        keys this term reads: a record of only those keys works."""
        needs = self.cls.needs(dataclasses.asdict(self.cls().params))
        assert isinstance(needs, set) and all(isinstance(k, str) for k in needs)
        assert needs <= set(self.record), f"needs() names keys the contract's record lacks: {needs - set(self.record)}"
        self.cls()({k: v for k, v in self.record.items() if k in needs})  # enough: nothing undeclared is read

    def test_missing_record_key_names_it(self):
        for key in self.required:
            rec = {k: v for k, v in self.record.items() if k != key}
            with pytest.raises(KeyError, match=key):
                self.cls()(rec)

    def test_hand_computed_cases(self):
        assert self.cases
        for params, record, expected in self.cases:
            got = self.cls(params)(record)
            assert math.isclose(got, expected, rel_tol=1e-12, abs_tol=1e-12), (params, record, got, expected)

    def test_registered_under_its_entry_point(self):
        eps = {ep.name: ep for ep in metadata.entry_points(group="jt.rewards")}
        if self.entry not in eps:
            pytest.skip(f"jt.rewards entry point '{self.entry}' not registered yet (pyproject)")
        from toolkit import plugins

        plugins.refresh()
        assert plugins.load("reward", self.entry) is self.cls
