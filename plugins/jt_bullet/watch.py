"""The termination rules of an episode, checked inside the simulator's substep loop.

``Checker`` evaluates a ``toolkit.interfaces.Watch`` at every ``check_every``-th substep of a
control step (and at its last): it logs the recorded quantities, then finds the first contact
rule that fires. A firing ``"fail"`` rule ends the step before anything else is noted at that
substep; otherwise the first touch of each watched body is noted (``touched``), then a
``"success"`` rule (with its ``clear_of`` test) may end the step, then the time limit.
"""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from toolkit.interfaces.simulator import Watch

_SHAPES = {"time": (), "com": (3,), "root": (7,)}


def empty_samples(watch: Optional[Watch]) -> dict[str, np.ndarray]:
    """Zero-row sample arrays of every quantity ``watch`` records."""
    return {k: np.zeros((0, *_SHAPES[k])) for k in (watch.record if watch is not None else ())}


class Checker:
    """One control step's evaluation of ``watch`` on simulator ``sim`` (``n`` substeps).

    Args:
        sim: the ``BulletSimulator`` (its ``contacts``, ``near``, ``link_states``, ``time``).
        watch: the rules and records; None checks nothing.
        n: substeps of this control step.
    """

    def __init__(self, sim: Any, watch: Optional[Watch], n: int) -> None:
        self.sim, self.watch, self.n = sim, watch, int(n)
        active = watch is not None and bool(watch.rules or watch.touches or watch.record
                                            or watch.time_limit is not None)
        self.active = active
        for key in (watch.record if watch is not None else ()):
            if key not in _SHAPES:
                raise ValueError(f"Watch.record: unknown quantity {key!r}; choose from {sorted(_SHAPES)}")
        self.every = max(1, int(watch.check_every)) if watch is not None else 1
        self.samples: dict[str, list] = {k: [] for k in (watch.record if watch is not None else ())}
        self.touched: dict[int, tuple[int, ...]] = {}
        self.outcome, self.reason = "", ""
        self._need_contacts = active and bool(watch.rules or watch.touches)

    def after_substep(self, k: int, q: np.ndarray) -> bool:
        """Check after substep ``k`` (0-based), state ``q``, when it is a checked one; True ends the step."""
        if not self.active or ((k + 1) % self.every and k + 1 < self.n):
            return False
        w, sim = self.watch, self.sim
        if self.samples:
            self._record(q)
        pts = sim.contacts() if self._need_contacts else []
        fired = None
        for rule in w.rules:
            if any(other == rule.body and (rule.links is None or link in rule.links)
                   and link not in rule.except_links for other, link in pts):
                if rule.outcome == "fail" or rule.clear_of is None or rule.clear_of < 0 \
                        or not sim.near(rule.clear_of, rule.margin):
                    fired = rule
                    break
        if fired is not None and fired.outcome == "fail":
            self.outcome, self.reason = fired.outcome, fired.reason
            return True
        for body in w.touches:
            if body not in self.touched:
                links = sorted({int(link) for other, link in pts if other == body})
                if links:
                    self.touched[body] = tuple(links)
        if fired is not None:
            self.outcome, self.reason = fired.outcome, fired.reason
            return True
        if w.time_limit is not None and sim.time >= w.time_limit - 1e-9:
            self.outcome, self.reason = w.time_limit_outcome, w.time_limit_reason
            return True
        return False

    def _record(self, q: np.ndarray) -> None:
        """Log the recorded quantities of the state ``q`` just integrated: time, the CoM by forward
        kinematics of ``q``, and the root pose (``q[:7]``)."""
        smp = self.samples
        if "time" in smp:
            smp["time"].append(self.sim.time)
        if "com" in smp:
            smp["com"].append(self.sim.com_now(q))
        if "root" in smp:
            smp["root"].append(q[:7].copy())

    def result(self, failed: bool, reason: str) -> dict[str, Any]:
        """``outcome``, ``reason`` (a failed simulation wins), ``touched``, ``samples``."""
        samples = {k: np.asarray(v, dtype=float).reshape(-1, *_SHAPES[k]) for k, v in self.samples.items()}
        if failed:
            return {"outcome": "fail", "reason": reason, "touched": self.touched, "samples": samples}
        return {"outcome": self.outcome, "reason": self.reason if self.outcome else reason,
                "touched": self.touched, "samples": samples}
