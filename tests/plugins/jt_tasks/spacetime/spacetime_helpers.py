"""Helpers shared by the spacetime tests (imported by name, not a conftest)."""

from __future__ import annotations


def make_spec(**kw):
    """A spacetime spec on the run clip with the FFC + FBC action and dense SPD."""
    from jt_tasks.spacetime.env import SpacetimeSpec
    from jt_tasks.spacetime.reference import resolve_clip

    clip = kw.pop("clip", "run")
    base = dict(clip=clip, sim={"spd": {"name": "df"}}, action={"name": "ffc_fbc", "clip": resolve_clip(clip)})
    base.update(kw)
    return SpacetimeSpec(**base)


def make_env(seed: int = 0, **kw):
    from jt_tasks.spacetime.env import SpacetimeEnv

    return SpacetimeEnv(make_spec(**kw), seed=seed)
