"""The contract every jt curriculum meets; each curriculum's test module subclasses it.

A subclass sets ``cls`` and ``entry`` (registry name, also its ``curriculum/<entry>.yaml`` in a
config root: jt's ``conf/`` or a ``jt.config`` package the plugin ships) and ``stream(n)``: ``n``
synthetic iterations as ``(episodes, scalar stats, samples)``. Usage::

    from toolkit.testing.curriculum import CurriculumContract

    class TestMine(CurriculumContract):
        cls, entry = MyCurriculum, "mine"
        def stream(self, n):
            return [([{"success": 1.0}], {"success_rate": 1.0}, 64)] * n
"""

from __future__ import annotations

import copy
import dataclasses
from importlib import metadata
from pathlib import Path
from typing import Any, ClassVar

import pytest
from omegaconf import OmegaConf

from toolkit.interfaces.curriculum import Curriculum


def iteration_stats(scalars: dict[str, float], episodes: list[dict[str, float]]) -> Any:
    """The trainer's own stats object (a dict of floats with ``.episodes``)."""
    from toolkit.rl.ppo import IterationStats

    return IterationStats(dict(scalars), list(episodes))


class CurriculumContract:
    """Config with defaults, numeric state, exact state round trips (dict, HDF5, trainer hook)."""

    cls: ClassVar[type]
    entry: ClassVar[str]
    n_iterations: ClassVar[int] = 40

    def make(self, params: Any = None):
        return self.cls(params)

    def yaml_path(self) -> Path:
        """``curriculum/<entry>.yaml`` in the first config root that has it (jt's ``conf/``, then
        each ``jt.config`` package)."""
        from toolkit.config import _group_dirs

        for root in _group_dirs():
            path = Path(root) / "curriculum" / f"{self.entry}.yaml"
            if path.is_file():
                return path
        raise AssertionError(f"curriculum/{self.entry}.yaml is in no config root")

    def stream(self, n: int) -> list[tuple[list[dict], dict[str, float], int]]:  # pragma: no cover
        raise NotImplementedError

    def feed(self, cur, items, start: int = 0) -> list[tuple[dict, dict]]:
        """Run ``items`` through ``on_iteration``; the state and env attributes after each."""
        out = []
        for i, (eps, scalars, samples) in enumerate(items, start=start + 1):
            attrs = cur.on_iteration(i, samples, iteration_stats(scalars, eps))
            out.append((dict(cur.state()), dict(attrs)))
        return out

    # ------------------------------------------------------------------ tests

    def test_is_a_curriculum_with_a_config(self):
        cur = self.make()
        assert isinstance(cur, Curriculum) and self.cls.summary()
        assert isinstance(cur.params, self.cls.Config)
        for f in dataclasses.fields(self.cls.Config):
            assert f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING

    def test_state_and_env_attrs_are_plain_numbers(self):
        cur = self.make()
        self.feed(cur, self.stream(5))
        for v in list(cur.state().values()) + list(cur.env_attrs().values()):
            assert type(v) in (int, float), v

    def test_the_stream_changes_the_difficulty(self):
        cur = self.make()
        before = cur.env_attrs()
        self.feed(cur, self.stream(self.n_iterations))
        assert cur.env_attrs() != before  # the synthetic stream is long enough to step

    def test_load_state_continues_identically(self):
        items = self.stream(self.n_iterations)
        half = len(items) // 2
        a = self.make()
        self.feed(a, items[:half])
        b = self.make()
        b.load_state(copy.deepcopy(a.state()))
        assert b.state() == a.state() and b.env_attrs() == a.env_attrs()
        assert self.feed(a, items[half:], half) == self.feed(b, items[half:], half)

    def test_state_survives_a_real_hdf5_checkpoint(self, tmp_path):
        from toolkit.rl import checkpoint as ckpt

        items = self.stream(self.n_iterations)
        half = len(items) // 2
        a = self.make()
        self.feed(a, items[:half])
        path = ckpt.save(tmp_path / "c.h5", {"extra": {"curriculum": a.state()}}, {})
        saved = ckpt.load(path)[0]["extra"]["curriculum"]
        b = self.make()
        b.load_state(saved)
        assert self.feed(a, items[half:], half) == self.feed(b, items[half:], half)

    def test_hook_resumes_from_the_trainers_extra(self):
        items = self.stream(self.n_iterations)
        half = len(items) // 2
        whole = self.make()
        extra_whole = whole.bind({})
        expected = self.feed(whole, items)
        first = self.make()
        extra = first.bind({})
        assert self.feed(first, items[:half]) == expected[:half]
        assert extra["curriculum"] == first.state()
        # a resumed run: a fresh curriculum bound to a dict the trainer then refills in place
        second = self.make()
        extra2 = second.bind({})
        extra2.clear()
        extra2.update(copy.deepcopy(extra))
        assert self.feed(second, items[half:], half) == expected[half:]
        assert extra2 == extra_whole

    def test_bad_saved_state_rejected(self):
        cur = self.make()
        state = dict(cur.state())
        state["level"] = 10_000
        with pytest.raises(ValueError):
            cur.load_state(state)

    def test_yaml_selects_and_the_config_holds_the_defaults(self):
        """One source: the YAML names the curriculum; composition types it by the Config, whose
        defaults (the paper's values, each field documented) are what the plugin receives."""
        from toolkit.config import compose

        node = OmegaConf.load(self.yaml_path())
        assert node.name == self.entry and set(node) == {"name"}
        typed = compose([f"curriculum={self.entry}", "task=zdt1"], run_checks=False).curriculum  # typing only
        assert typed.name == self.entry
        assert self.make(typed).params == self.cls.Config()

    def test_unknown_key_is_one_clear_error(self):
        from toolkit.errors import JtError

        with pytest.raises(JtError, match="unknown key.*valid keys"):
            self.make({"name": self.entry, "no_such_key": 1})

    def test_registered_under_its_entry_point(self):
        eps = {ep.name for ep in metadata.entry_points(group="jt.curricula")}
        if self.entry not in eps:
            pytest.skip(f"jt.curricula entry point '{self.entry}' not registered yet (pyproject)")
        from toolkit import plugins

        plugins.refresh()
        assert plugins.load("curriculum", self.entry) is self.cls
