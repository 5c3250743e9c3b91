"""Initial-state adaptation of spacetime bounds (``002`` §4.3): importance sampling and evolution.

Both live in the learner's process and are fed by PPO's per-iteration statistics
(``toolkit.rl.ppo.IterationStats``): ``starts`` (every episode started in the batch, with the
TD(λ) target of its first state) and ``visits`` (every state the env reported, with its target).
The result goes to every environment as the attribute ``start_sampling`` (``StartSampler.payload``),
which ``SpacetimeEnv.start`` draws its episode starts from.

* Importance sampling of start phases (002 §4.3.1 eq 11): the clip is divided into ``n``
  segments (10, 002 §4.3.1 / authors' code); ``w_k`` is a running average (0.99, authors' code)
  of the λ-return targets of the episode-start states in segment ``k``, updated every iteration;
  ``p(k) = (1 − u) softmax(−w / v)_k + u / n`` with ``u = 0.2`` (002 §4.3.1). ``v``: paper
  ``(max w − min w) / 3``; code ``(max w − min w) + 0.01`` (``is_probabilities``).
* Initial-state evolution (002 §4.3.2 eq 12): a buffer of ``m`` states per segment; after every
  iteration, ``m`` states are drawn without replacement from the segment's visited states and its
  old buffer with the Boltzmann probabilities of their estimated returns ``w_l``: paper
  ``exp(−w_l / v)``, ``v = max − min`` (favours low values); code ``exp(3 (w_l − max) / (max − min
  + 0.01))`` (favours high values), old values × 0.95 first (``boltzmann_probabilities``). An empty
  buffer is the reference itself (a start at a uniform phase inside the segment).

Worked example (research notes): ``w = [10, 15, 20]`` gives eq 11 ``[0.695, 0.207, 0.098]``
(paper) / ``[0.472, 0.312, 0.216]`` (code) and eq 12 ``[0.507, 0.307, 0.186]`` (paper) /
``[0.039, 0.176, 0.785]`` (code); tests/plugins/jt_tasks/spacetime/test_spacetime_sampling.py.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Optional

import numpy as np

READINGS = ("paper", "code")


def segment_of(phase: Any, n: int) -> np.ndarray:
    """Segment index ``(...,)`` int of phases in ``[0, 1]`` (a phase of 1 or more: the last)."""
    return np.clip(np.floor(np.asarray(phase, dtype=float) * n), 0, n - 1).astype(int)


def is_probabilities(w: np.ndarray, u: float = 0.2, reading: str = "paper") -> np.ndarray:
    """Start-segment probabilities ``(n,)`` of eq 11 from the segments' estimated returns ``w`` ``(n,)``.

    ``p = (1 − u) softmax(−w / v) + u / n``; ``v = (max − min) / 3`` (paper; all-equal ``w``:
    uniform) or ``(max − min) + 0.01`` (authors' code).
    """
    w = np.asarray(w, dtype=float).reshape(-1)
    n = w.size
    gap = float(w.max() - w.min()) if n else 0.0
    v = gap / 3.0 if reading == "paper" else gap + 0.01
    soft = np.full(n, 1.0 / n) if v <= 0 else np.exp(-(w - w.min()) / v)
    soft = soft / soft.sum()
    return (1.0 - u) * soft + u / n


def boltzmann_probabilities(w: np.ndarray, reading: str = "paper") -> np.ndarray:
    """Selection probabilities ``(N,)`` of eq 12 from candidates' estimated returns ``w`` ``(N,)``.

    Paper: ``exp(−w_l / v) / Σ``, ``v = max − min`` (all-equal ``w``: uniform); authors' code:
    ``exp(3 (w_l − max) / (max − min + 0.01))``, normalised.
    """
    w = np.asarray(w, dtype=float).reshape(-1)
    if w.size == 0:
        return w
    gap = float(w.max() - w.min())
    if reading == "paper":
        z = np.zeros_like(w) if gap <= 0 else -(w - w.min()) / gap
    else:
        z = 3.0 * (w - w.max()) / (gap + 0.01)
    p = np.exp(z)
    return p / p.sum()


def boltzmann_draw(w: np.ndarray, m: int, rng: np.random.Generator, reading: str = "paper") -> np.ndarray:
    """Indices of ``min(m, N)`` candidates drawn without replacement by eq 12 (all of them if ``N <= m``)."""
    w = np.asarray(w, dtype=float).reshape(-1)
    if w.size <= m:
        return np.arange(w.size)
    return np.sort(rng.choice(w.size, size=m, replace=False, p=boltzmann_probabilities(w, reading)))


@dataclasses.dataclass
class SamplingParams:
    """The knobs of ``StartSampler``, all required and named as the ``task.*`` settings they come
    from: their defaults and sources live once, in ``SpacetimeConfig``, which builds this with
    ``sampling_params()`` (filling in a reading's defaults where a setting is null); ``decay`` is
    the only derived one (0.95 with the authors' code's reading of eq 12, else 1)."""

    importance_sampling: bool
    n_segments: int
    is_uniform: float
    is_average: float
    is_reading: str
    evolution: bool
    evolution_size: int
    evolution_share: float
    evolution_warmup: int
    evolution_reading: str
    decay: float


class StartSampler:
    """Eq 11 start-phase weights and eq 12 start-state buffers, kept in ``extra`` (checkpointed).

    Args:
        params: the knobs.
        extra: PPO's ``extra`` dict (replaced in place on resume, so state is read from it lazily).
        seed: seeds the Boltzmann draws (one generator per iteration: a resume draws the same).
        state_dim: length of a visited state (``SpacetimeEnv.visit_state``); None: from the first visits.
    """

    KEY = "start_sampling"

    def __init__(self, params: SamplingParams, extra: dict, seed: int, state_dim: Optional[int] = None) -> None:
        self.p, self.extra, self.seed = params, extra, int(seed)
        n, m = params.n_segments, params.evolution_size
        d = 0 if state_dim is None else int(state_dim)
        self.extra.setdefault(self.KEY, {
            "w": np.zeros(n), "seen": np.zeros(n), "history": np.zeros((0, 1 + 3 * n)),
            "states": np.zeros((n, m, d)), "values": np.zeros((n, m)), "count": np.zeros(n, dtype=np.int64)})

    @property
    def state(self) -> dict:
        return self.extra[self.KEY]

    def probabilities(self) -> np.ndarray:
        """Eq 11 start-segment probabilities ``(n,)`` now (uniform with importance sampling off)."""
        n = self.p.n_segments
        if not self.p.importance_sampling:
            return np.full(n, 1.0 / n)
        return is_probabilities(self.state["w"], self.p.is_uniform, self.p.is_reading)

    def record_starts(self, starts: list[dict]) -> None:
        """Running-average update of ``w`` from the episode starts' ``start_phase`` and ``target``."""
        st, n = self.state, self.p.n_segments
        if not starts:
            return
        seg = segment_of([s["start_phase"] for s in starts], n)
        tgt = np.array([float(s["target"]) for s in starts])
        for k in range(n):
            mask = seg == k
            if mask.any():
                st["w"][k] = self.p.is_average * st["w"][k] + (1.0 - self.p.is_average) * float(tgt[mask].mean())
                st["seen"][k] += float(mask.sum())

    def refresh(self, visits: list[dict], iteration: int) -> None:
        """Eq 12: redraw every segment's buffer from its visited states and its old buffer."""
        st, n, m = self.state, self.p.n_segments, self.p.evolution_size
        rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([self.seed, 12, int(iteration)])))
        d = int(st["states"].shape[2])
        if visits:
            states = np.stack([np.asarray(v["state"], dtype=float).reshape(-1) for v in visits])
            values = np.array([float(v["target"]) for v in visits])
            if states.shape[1] != d:
                if st["count"].any():
                    raise ValueError(f"visited states of length {states.shape[1]}, buffers hold {d}")
                d = states.shape[1]
                st["states"] = np.zeros((n, m, d))
        else:
            states, values = np.zeros((0, d)), np.zeros(0)
        seg = segment_of(states[:, 0], n) if len(states) else np.zeros(0, dtype=int)
        new_s, new_v, new_c = np.zeros((n, m, d)), np.zeros((n, m)), np.zeros(n, dtype=np.int64)
        for k in range(n):
            c = int(st["count"][k])
            cand_s = np.concatenate([st["states"][k, :c], states[seg == k]])
            cand_v = np.concatenate([st["values"][k, :c] * self.p.decay, values[seg == k]])
            pick = boltzmann_draw(cand_v, m, rng, self.p.evolution_reading)
            new_c[k] = len(pick)
            new_s[k, :len(pick)], new_v[k, :len(pick)] = cand_s[pick], cand_v[pick]
        st["states"], st["values"], st["count"] = new_s, new_v, new_c

    def update(self, iteration: int, samples: int, stats: Any) -> dict[str, Any]:
        """PPO's ``on_iteration``: update eq 11 and eq 12, log the distribution, return the payload."""
        if self.p.importance_sampling:
            self.record_starts(list(getattr(stats, "starts", []) or []))
        if self.p.evolution:
            self.refresh(list(getattr(stats, "visits", []) or []), iteration)
        st = self.state
        probs = self.probabilities()
        row = np.concatenate([[float(samples)], probs, st["w"], st["count"].astype(float)])
        st["history"] = np.vstack([st["history"].reshape(-1, row.size), row])
        return {self.KEY: self.payload(iteration)}

    def payload(self, iteration: int) -> dict[str, Any]:
        """What every env gets: ``probs`` ``(n,)`` and, once the evolution is on, ``states`` ``(n, m, d)``,
        ``count`` ``(n,)`` and ``share`` (the fraction of starts drawn from a buffer)."""
        out: dict[str, Any] = {"probs": self.probabilities()}
        if self.p.evolution and iteration >= self.p.evolution_warmup:
            st = self.state
            out.update(states=st["states"].copy(), count=st["count"].copy(), share=float(self.p.evolution_share))
        return out

    def history(self) -> Optional[dict[str, np.ndarray]]:
        """Per iteration: ``samples`` ``(n_it,)``, ``probs``, ``w`` and ``count`` ``(n_it, n)``."""
        h, n = self.state["history"], self.p.n_segments
        if h.size == 0:
            return None
        h = h.reshape(-1, 1 + 3 * n)
        return {"samples": h[:, 0], "probs": h[:, 1:1 + n], "w": h[:, 1 + n:1 + 2 * n], "count": h[:, 1 + 2 * n:]}
