"""Fixture ``worlds``: every thesis character loaded once per session (see dynamics_worlds)."""

from __future__ import annotations

from typing import Any

import pytest
from dynamics_worlds import World, _make


@pytest.fixture(scope="session")
def worlds() -> Any:
    """``worlds(name, fixed=False) -> World``, created on first use and kept for the session."""
    import pybullet as pb

    cache: dict = {}

    def get(name: str, fixed: bool = False) -> World:
        key = (name, fixed)
        if key not in cache:
            cache[key] = _make(name, fixed)
        return cache[key]

    yield get
    for w in cache.values():
        pb.disconnect(w.client)
