"""Every task with every installed action space, reward, curriculum and character, one group varied
at a time from the task's smoke preset (issue 30): composition either gives a config or refuses it
in one ``JtError`` line before anything runs: never another exception, never a store. The pairs
that used to fail only mid-run are among the refused."""

from __future__ import annotations

import pytest

from toolkit import plugins
from toolkit.errors import JtError

GROUPS = {"action": "action", "reward": "reward", "curriculum": "curriculum", "character": "character"}


def _choices(kind: str) -> list[str]:
    if kind in ("reward", "character"):  # sets of terms / the simulator's characters: the config group's files
        from pathlib import Path

        return sorted(p.stem for p in (Path(__file__).resolve().parents[2] / "conf" / kind).glob("*.yaml"))
    return plugins.names(kind)


def _outcome(overrides: list[str], store) -> str:
    from toolkit.config import compose

    try:
        compose([*overrides, f"store={store}"])
        return "ok"
    except JtError as e:
        assert "\n" not in str(e), (overrides, str(e))
        return "refused: " + str(e)


@pytest.mark.parametrize("task", plugins.names("task"))
def test_each_choice_composes_or_is_one_line(task, tmp_path):
    outcomes = {}
    store = tmp_path / "store"
    for group, kind in GROUPS.items():
        for choice in _choices(kind):
            outcomes[f"{group}={choice}"] = _outcome([f"task={task}", "experiment=smoke", f"{group}={choice}"], store)
    assert not store.exists()
    assert any(v == "ok" for v in outcomes.values()), outcomes


@pytest.mark.parametrize("overrides, words", [
    (["task=getup", "reward=highjump"], "reads record key(s) success"),
    (["task=spacetime", "action=cvae"], "needs condition from the task"),
    (["task=spacetime", "character=laikago"], "needs character=humanoid"),
    (["task=spacetime", "reward=getup"], "does not read a reward group"),
    (["task=spacetime", "curriculum=terrain"], "does not read a curriculum group"),
    (["task=getup", "curriculum=bar_height"], "drives bar_height"),
    (["task=getup", "action=ffc_fbc"], "needs phase from the task"),
])
def test_the_pairs_that_failed_mid_run_are_refused_first(overrides, words, tmp_path):
    out = _outcome([*overrides, "experiment=smoke"], tmp_path / "store")
    assert out.startswith("refused") and words in out, out
