"""Shared helpers of the get-up tests."""

from __future__ import annotations

from typing import Any

import numpy as np


def sim_groups() -> dict:
    return {"sim": {"name": "bullet", "friction": 1.0}, "spd": {"name": "df"}, "character": {"name": "humanoid"}}


def standing_sim() -> Any:
    """A bullet simulator holding the last (standing) frame of getup_facedown on flat ground."""
    from jt_tasks.getup.initial import clip_pose
    from toolkit.policy.env import load_simulator

    sim = load_simulator(sim_groups())
    q, qd = clip_pose("getup_facedown", False, frame=-1)
    sim.reset(q, qd)
    return sim


def make_task(*overrides: str):
    """A get-up task with raw actions, no fallen starts, flat ground and no curriculum (the stage-1 tests')."""
    from toolkit import plugins
    from toolkit.config import compose, validate

    cfg = validate(compose(["task=getup", "action=raw", "task.n_fallen=0", "task.terrain=null", "~curriculum",
                            "task.eval_regions=[flat]", *overrides]))
    return plugins.load("task", "getup")(cfg)


class Still:
    """A policy that holds every PD target at zero offset (raw actions: the rest pose)."""

    def __init__(self, n: int) -> None:
        self.n = n

    def act(self, obs: np.ndarray) -> np.ndarray:
        return np.zeros(self.n)
