"""Every task with every installed action space, reward, curriculum and character, one group varied
at a time from the task's smoke preset (issue 30): composition either gives a config or refuses it
in one ``JtError`` line before anything runs: never another exception, never a store. The pairs
that used to fail only mid-run are among the refused; every accepted pair of a policy task builds
its environment at the curriculum's first difficulty and takes its first step (compose-only where
the action space would first train a prior)."""

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


def _compose(overrides: list[str], store):
    """The composed config, or None where composition refuses in one line."""
    from toolkit.config import compose

    try:
        return compose([*overrides, f"store={store}"])
    except JtError:
        return None


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
    store = tmp_path / "store"
    outcomes = {"(the smoke preset alone)": _outcome([f"task={task}", "experiment=smoke"], store)}
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
    (["task=highjump", "action=ffc_fbc"], "needs phase from the task"),
    (["task=highjump", "reward=getup"], "reads record key(s) h, target_h"),
    (["task=highjump", "curriculum=terrain"], "drives terrain_level"),
    (["task=obstacle", "curriculum=bar_height"], "drives bar_height"),
    (["task=runup", "reward=highjump"], "does not read a reward group"),
    (["task=zdt1", "character=laikago"], "does not read a character group"),
    (["task=pose_prior", "agent=ppo_getup"], "does not read an agent group"),
    (["task=strategy_landscape", "character.kp=5"], "drop character.kp=5"),
])
def test_the_pairs_that_failed_mid_run_are_refused_first(overrides, words, tmp_path):
    out = _outcome([*overrides, "experiment=smoke"], tmp_path / "store")
    assert out.startswith("refused") and words in out, out


PRIOR_FREE = ("raw", "ffc_fbc")  # the others decode through a trained prior: composing one is the check


def _policy_tasks() -> list[str]:
    from toolkit.policy.task import PolicyTask

    return [t for t in plugins.names("task") if issubclass(plugins.load("task", t), PolicyTask)]


def _first_step(task: str, cfg) -> tuple[int, float]:
    """Build ``task``'s environment as training does (the curriculum's first difficulty set on it),
    reset it and step it once with a zero action: ``(observation size, reward)``."""
    import numpy as np
    from omegaconf import OmegaConf

    env = plugins.load("task", task)(cfg).make_env(seed=0)
    try:
        cur = cfg.get("curriculum")
        if cur is not None and "name" in cur:
            attrs = plugins.load("curriculum", str(cur.name))(cur).env_attrs()
            for k, v in attrs.items():
                assert hasattr(env, k), f"curriculum={cur.name} drives {k}, which task={task}'s env lacks"
                setattr(env, k, v)
        obs, _ = env.reset(seed=0)
        obs2, reward, *_ = env.step(np.zeros(env.action_space.shape, np.float32))
        assert obs.shape == obs2.shape == env.observation_space.shape, OmegaConf.to_yaml(cfg)
        assert np.isfinite(reward) and np.isfinite(obs2).all()
        return int(obs.size), float(reward)
    finally:
        env.close()


@pytest.mark.parametrize("task", _policy_tasks())
def test_each_accepted_choice_takes_its_first_step(task, tmp_path):
    from omegaconf import OmegaConf

    store, seen, stepped = tmp_path / "store", set(), []
    for group, kind in GROUPS.items():
        for choice in _choices(kind):
            cfg = _compose([f"task={task}", "experiment=smoke", f"{group}={choice}"], store)
            if cfg is None:
                continue
            key = OmegaConf.to_yaml(cfg)
            if key in seen:  # the smoke preset's own choice: stepped once
                continue
            seen.add(key)
            if str(cfg.action.name) in PRIOR_FREE:
                _first_step(task, cfg)
                stepped.append(f"{group}={choice}")
    assert stepped, f"task={task}: no accepted choice ran"
    assert not store.exists()
