"""Get-ups from the clips' own start poses, perturbed (issue 29's stage 1; ours, not 003).

``clip_start_options`` lists the reset options of ``n`` deterministic get-ups: the clip curves in
turn (facedown, its mirror, faceup, its mirror), each start perturbed by ``noise`` rad with its own
seed, so that the same ``n`` and ``seed`` give the same starts. ``clip_start_success`` runs them
with a policy's mean action and reports the share that got up and stood (``success``, 003 §6.3's
rule as ``GetupEnv`` applies it) and the share that reached the standing height (``got_up``).

``ClipStartTraining`` is PPO's ``on_iteration`` hook that does the same every ``eval_every``
iterations during training and keeps ``(samples, success, got_up)`` rows in
``extra["eval_history"]`` (checkpointed, so a resumed run keeps them).
"""

from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

EVAL_KEY = "eval_history"


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


def run_episode(env: Any, model: Any, options: dict) -> dict[str, Any]:
    """One deterministic episode from ``env.reset(seed=0, options)``; its final info."""
    from toolkit.execution import stopping

    stopping.check()  # a safe point (SIGTERM): between episodes
    obs, _ = env.reset(seed=0, options=options)
    done, info = False, {}
    while not done:
        obs, _, te, tr, info = env.step(model.act(obs).astype(np.float32))
        done = te or tr
    return dict(info)


def clip_start_success(env: Any, model: Any, n: int, noise: float, seed: int = 0) -> dict[str, Any]:
    """``success``, ``got_up`` (shares) and ``infos`` (one per episode) of ``n`` deterministic
    get-ups from perturbed clip starts (``clip_start_options``)."""
    infos = [run_episode(env, model, o) for o in clip_start_options(env.curves, n, noise, seed)]
    return {"success": float(np.mean([i.get("success", 0.0) for i in infos])),
            "got_up": float(np.mean([i.get("got_up", 0.0) for i in infos])), "infos": infos}


class ClipStartTraining:
    """An ``on_iteration`` hook: every ``eval_every`` iterations, ``n`` deterministic get-ups from
    perturbed clip starts with the learner's model (``stats.model``).

    Args:
        make_env: ``make_env() -> GetupEnv`` (built and closed each time).
        n: episodes per evaluation; noise: rad (``task.eval_start_noise``).
        eval_every: iterations between evaluations (0: none).
        extra: PPO's ``extra`` (the rows live there).
        then: the task's own hook, called first (its return value is returned).
        progress: optional ``progress(fraction, message)``; total: the run's sample budget.
    """

    def __init__(self, make_env: Callable[[], Any], n: int, noise: float, eval_every: int, extra: dict,
                 then: Callable[[int, int, Any], dict], progress: Optional[Callable] = None, total: int = 1) -> None:
        self.make_env, self.n, self.noise, self.eval_every = make_env, int(n), float(noise), int(eval_every)
        self.extra, self.then, self.progress, self.total = extra, then, progress, max(int(total), 1)
        self.extra.setdefault(EVAL_KEY, np.zeros((0, 3)))

    def __call__(self, iteration: int, samples: int, stats: Any) -> dict[str, Any]:
        out = self.then(iteration, samples, stats)
        model = getattr(stats, "model", None)
        if self.eval_every > 0 and self.n > 0 and model is not None and iteration % self.eval_every == 0:
            env = self.make_env()
            try:
                res = clip_start_success(env, model, self.n, self.noise, seed=10_000)  # not the final evaluation's
            finally:
                env.close()
            self.extra[EVAL_KEY] = np.vstack([self.history(), [float(samples), res["success"], res["got_up"]]])
            if self.progress is not None:
                self.progress(min(samples / self.total, 1.0),
                              f"clip starts: success {res['success']:.2f}, got up {res['got_up']:.2f}")
        return out

    def history(self) -> np.ndarray:
        """Rows ``(samples, success, got_up)`` ``(n_evaluations, 3)``."""
        return np.asarray(self.extra.get(EVAL_KEY, np.zeros((0, 3))), dtype=float).reshape(-1, 3)
