"""Check that an environment follows the gymnasium API (used on every jt task's env)."""

from __future__ import annotations

import warnings
from typing import Any


def check_gym_env(env: Any, strict: bool = False) -> list[str]:
    """Run ``gymnasium.utils.env_checker.check_env`` on ``env`` (an instance, not a factory).

    Args:
        env: the environment; it is reset and stepped by the checker.
        strict: turn the checker's warnings into an error.

    Returns:
        The warning messages the checker emitted (empty when clean).

    Raises:
        AssertionError / TypeError / ValueError: from the checker when the API is violated;
        ``RuntimeError`` when ``strict`` and any warning was emitted.
    """
    from gymnasium.utils.env_checker import check_env

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env, skip_render_check=True)
    messages = [str(w.message) for w in caught]
    if strict and messages:
        raise RuntimeError("gymnasium env checker warnings:\n" + "\n".join(messages))
    return messages
