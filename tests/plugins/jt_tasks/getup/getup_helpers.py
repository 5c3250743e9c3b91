"""Shared helpers of the get-up tests."""

from __future__ import annotations

from typing import Any


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
