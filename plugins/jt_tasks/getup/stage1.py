"""Get-ups from the clips' own start poses, perturbed (issue 29's stage 1; ours, not 003).

``clip_start_options`` lists the reset options of ``n`` deterministic get-ups: the clip curves in
turn (facedown, its mirror, faceup, its mirror), each start perturbed by ``noise`` rad with its own
seed, so that the same ``n`` and ``seed`` give the same starts. ``clip_start_success`` runs them
with a policy's mean action and reports the share that got up and stood (``success``, 003 §6.3's
rule as ``GetupEnv`` applies it) and the share that reached the standing height (``got_up``).

``ClipStartTraining`` does the same every ``eval_every`` iterations during training: a
``toolkit.policy.periodic.PeriodicEvaluation`` whose ``(samples, success, got_up)`` rows live in
``extra["eval_history"]`` (checkpointed, so a resumed run keeps them).
"""

from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

from toolkit.policy.episodes import opened_env, rollout
from toolkit.policy.periodic import PeriodicEvaluation


def clip_start_options(curves: list, n: int, noise: float, seed: int = 0) -> list[dict]:
    """Reset options of ``n`` perturbed clip starts: the curves with a clip in turn.

    Args:
        curves: the env's ``FeatureCurve`` s (those without a clip are skipped).
        n: episodes.
        noise: rad, joint perturbation of each start.
        seed: the first episode's noise seed (episode ``i`` uses ``seed + i``).

    Raises:
        ValueError: no curve has a clip.
    """
    names = [c.name for c in curves if c.clip]
    if not names:
        raise ValueError("clip starts need a reference curve (a curve with a clip)")
    return [{"kind": "clip", "curve": names[i % len(names)], "noise": float(noise), "noise_seed": int(seed) + i}
            for i in range(int(n))]


def clip_start_success(env: Any, model: Any, n: int, noise: float, seed: int = 0) -> dict[str, Any]:
    """``success``, ``got_up`` (shares) and ``infos`` (one per episode) of ``n`` deterministic
    get-ups from perturbed clip starts (``clip_start_options``)."""
    infos = [dict(rollout(env, model, options=o).info) for o in clip_start_options(env.curves, n, noise, seed)]
    return {"success": float(np.mean([i.get("success", 0.0) for i in infos])),
            "got_up": float(np.mean([i.get("got_up", 0.0) for i in infos])), "infos": infos}


class ClipStartTraining(PeriodicEvaluation):
    """An ``on_iteration`` hook: every ``eval_every`` iterations, ``n`` deterministic get-ups from
    perturbed clip starts with the learner's model (``stats.model``); rows ``(samples, success,
    got_up)`` (``history()``, ``(n_evaluations, 3)``).

    Args:
        make_env: ``make_env() -> GetupEnv`` (built and closed each time).
        n: episodes per evaluation (0: none); noise: rad (``task.eval_start_noise``).
        eval_every: iterations between evaluations (0: none).
        extra: PPO's ``extra`` (the rows live there).
        then: the task's own hook, called first (its return value is returned).
        progress: optional ``progress(fraction, message)``; total: the run's sample budget.
    """

    def __init__(self, make_env: Callable[[], Any], n: int, noise: float, eval_every: int, extra: dict,
                 then: Callable[[int, int, Any], dict], progress: Optional[Callable] = None, total: int = 1) -> None:
        self.make_env, self.n, self.noise = make_env, int(n), float(noise)
        super().__init__(extra, ("success", "got_up"), int(eval_every) if self.n > 0 else 0, then=then,
                         progress=progress, total=total,
                         message=lambda v: f"clip starts: success {v[0]:.2f}, got up {v[1]:.2f}")

    def evaluate(self, model: Any) -> tuple[float, float]:
        """``(success, got_up)`` of ``n`` get-ups from clip starts whose noise seeds the final
        evaluation never uses (10 000 on)."""
        with opened_env(self.make_env) as env:
            res = clip_start_success(env, model, self.n, self.noise, seed=10_000)
        return res["success"], res["got_up"]
