"""A reverse curriculum over the clip starts inside the clip (ours, not ``003``; docs/getup.md).

With ``task.rsi`` > 0 a share of the clip starts begins at a random time of the clip (reference state
initialisation). ``StartWindow`` narrows those times to the clip's last part, ``[rsi_from · T, T]``,
and moves the window's front back by ``rsi_step`` whenever the newest band of starts,
``[rsi_from · T, (rsi_from + rsi_step) · T)``, succeeds (stands at the episode's end, the env's
``success``) in at least ``rsi_success`` of its last ``rsi_episodes`` training episodes: the policy
learns the end of the get-up first (the standing, then the rise from a crouch) and the start from
the ground last, each stage starting from states the previous one already solves (Florensa et al.
2017, "Reverse curriculum generation"). Starts at the clip's first pose (the share ``1 − rsi``),
rag-doll and standing starts are drawn as before.

It is PPO's ``on_iteration`` hook: it reads the iteration's finished episodes (``start_frac``, the
start's fraction of the clip, and ``success``), keeps its state in ``extra["rsi_window"]``
(checkpointed, so a resumed run goes on where it stopped) and returns ``{"rsi_from": value}`` for
the trainer to set on every environment.
"""

from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

KEY = "rsi_window"  #: its state in PPO's ``extra``: [rsi_from, then the band's outcomes, newest last]
MOVES_KEY = "rsi_window_moves"  #: rows (samples, rsi_from after the move) ``(n_moves, 2)``


class StartWindow:
    """The reverse curriculum's ``on_iteration`` hook (module docstring).

    Args:
        start: the window's first front, a fraction of the clip in [0, 1) (``task.rsi_from``).
        step: how far the front moves back on a success (``task.rsi_step``; 0: a fixed window).
        success: the band's success share that moves it (``task.rsi_success``).
        episodes: the band's training episodes that share is measured over (``task.rsi_episodes``).
        extra: PPO's ``extra`` (the state lives there).
        then: the hook this one wraps (called first; its attributes are passed on with this one's).
    """

    def __init__(self, start: float, step: float, success: float, episodes: int, extra: dict,
                 then: Optional[Callable[[int, int, Any], Any]] = None) -> None:
        self.start, self.step, self.success, self.episodes = float(start), float(step), float(success), int(episodes)
        self.extra, self.then = extra, then
        self.extra.setdefault(KEY, np.array([self.start]))
        self.extra.setdefault(MOVES_KEY, np.zeros((0, 2)))

    @property
    def front(self) -> float:
        """The window's front now: starts inside the clip are drawn in ``[front · T, T]``."""
        return float(np.asarray(self.extra[KEY], float).reshape(-1)[0])

    def outcomes(self) -> list[float]:
        """The newest band's outcomes since the front last moved (1 success, 0 not), oldest first."""
        return [float(x) for x in np.asarray(self.extra[KEY], float).reshape(-1)[1:]]

    def band(self, episode: dict) -> bool:
        """Whether a finished ``episode`` (its info) started in the newest band."""
        frac = episode.get("start_frac")
        if frac is None or not np.isfinite(float(frac)):
            return False
        frac, lo = float(frac), self.front - 1e-9
        return lo <= frac < lo + self.step if self.step > 0.0 else frac >= lo

    def __call__(self, iteration: int, samples: int, stats: Any) -> dict[str, Any]:
        out = self.then(iteration, samples, stats) if self.then is not None else None
        front, seen = self.front, self.outcomes()
        for e in list(getattr(stats, "episodes", []) or []):
            if self.band(e):
                seen.append(float(e.get("success", 0.0)))
        seen = seen[-self.episodes:]
        if self.step > 0.0 and front > 0.0 and len(seen) >= self.episodes and np.mean(seen) >= self.success - 1e-12:
            front, seen = max(0.0, round(front - self.step, 9)), []
            self.extra[MOVES_KEY] = np.vstack([self.moves(), [float(samples), front]])
        self.extra[KEY] = np.array([front, *seen])
        return {**dict(out or {}), "rsi_from": front}

    def moves(self) -> np.ndarray:
        """Rows ``(samples, front after the move)`` ``(n_moves, 2)``."""
        return np.asarray(self.extra.get(MOVES_KEY, np.zeros((0, 2))), dtype=float).reshape(-1, 2)
