"""Helpers shared by the run-up tests (not a conftest: the jumping tests import theirs by name)."""

from __future__ import annotations

FOSBURY_TARGET = {"omega_x": -3.0, "omega_z": 1.0, "v_z": -2.4}  # 000 Table 3 (alpha plays no part)
STRADDLE_TARGET = {"omega_x": 0.0, "omega_y": 0.0, "omega_z": 1.0}  # 000 Table 4


def make_spec(**kw):
    """A high-jump run-up spec with raw PD-target actions and dense SPD."""
    from jt_tasks.runup.env import RunupSpec

    base = dict(kind="highjump", target=dict(FOSBURY_TARGET), sim={"spd": {"name": "df"}}, action={"name": "raw"})
    base.update(kw)
    return RunupSpec(**base)


def make_env(seed: int = 0, **kw):
    from jt_tasks.runup.env import RunupEnv

    return RunupEnv(make_spec(**kw), seed=seed)
