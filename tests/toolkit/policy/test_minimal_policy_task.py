"""The minimal policy task of docs/writing-a-plugin.md runs on the layer as written: it trains,
rolls out, and leaves every artifact of a policy task; its env passes Gymnasium's checker."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))


@pytest.fixture()
def stand_cfg():
    from omegaconf import OmegaConf

    from toolkit.config import compose

    cfg = compose(["task=runup", "experiment=smoke"])  # smoke-sized PPO, raw actions
    OmegaConf.set_struct(cfg, False)
    cfg.task = {"name": "stand", "time_limit": 0.5, "filmstrip_frames": 2, "filmstrip_width": 32,
                "filmstrip_height": 24}
    return cfg


def test_the_documented_task_trains_and_writes_its_artifacts(stand_cfg, tmp_path):
    from stand_example import StandTask

    from toolkit.interfaces import EvalContext

    ev = StandTask(stand_cfg).evaluate({}, EvalContext(index=0, seed=0, workdir=tmp_path))
    assert ev.metrics["samples"] >= 128 and ev.history["mean_return"]
    for name in ("ppo.h5", "rollout.h5", "filmstrip.png", "motion.gif"):
        assert (tmp_path / name).is_file(), name
    assert set(ev.artifacts) == {"ppo.h5", "rollout.h5", "filmstrip.png", "motion.gif"}


def test_the_sample_budget_is_the_agent_groups_total_samples(stand_cfg, tmp_path):
    from stand_example import StandTask

    from toolkit.interfaces import EvalContext
    from toolkit.policy.train import agent_config

    ctx = EvalContext(index=0, seed=5, workdir=tmp_path)
    want = agent_config(stand_cfg.agent, 5).total_samples
    assert StandTask(stand_cfg).sample_budget(ctx) == want
    stand_cfg.agent.total_samples = want + 64
    assert StandTask(stand_cfg).sample_budget(ctx) == want + 64


def test_the_documented_env_passes_the_gymnasium_checker(stand_cfg):
    from gymnasium.utils.env_checker import check_env
    from stand_example import StandTask

    env = StandTask(stand_cfg).make_env(seed=0)
    try:
        check_env(env, skip_render_check=True)
    finally:
        env.close()


def test_the_documented_code_is_small():
    code = (Path(__file__).parent / "stand_example.py").read_text().splitlines()
    assert len([ln for ln in code if ln.strip()]) <= 250
