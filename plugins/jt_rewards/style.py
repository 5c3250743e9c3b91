"""Style reward terms of spacetime bounds (``002`` §3.3, eqs 4-5): kinetic energy and body volume.

Both are per-control-step factors in ``[0, 1]``, multiplied into the survival reward of 1
(``task=spacetime``'s ``style`` list, ``r = survival × style``).

* ``energy`` (eq 4): ``r = clamp((E_max − E) / (E_max − E_min), 0, 1)`` to decrease the energy,
  ``clamp((E − E_min) / (E_max − E_min), 0, 1)`` to increase it, ``[E_min, E_max] = [20, 100]`` J
  (002 §5.3.1); ``E`` = the bodies' kinetic energy minus ``½ |P_xz|² / M`` (the horizontal CoM
  motion removed). The record gives ``link_vel`` ``(n, 3)`` and ``masses`` ``(n,)``, and
  optionally the rotational part as ``rotational_energy`` (J); or ``kinetic_energy`` directly.
* ``volume`` (eq 5): ``r = exp(−V / α)`` to decrease, ``1 − exp(−V / α)`` to increase,
  ``α = 0.12 m³``; ``V`` = the volume of the convex hull of the joint positions ``joint_pos``
  ``(n, 3)`` (scipy's ``ConvexHull``; 0 for a degenerate hull).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from jt_rewards.base import RecordTerm
from toolkit.motion.style import hull_volume, kinetic_energy  # noqa: F401 - the terms' measures

MODES = ("decrease", "increase")


def _mode(term: RecordTerm) -> None:
    from toolkit.errors import JtError

    if term.params.mode not in MODES:
        raise JtError(f"reward term {term.term_name}: mode={term.params.mode!r}: decrease or increase")


class Energy(RecordTerm):
    """Kinetic-energy style reward (002 eq 4): low (or high) energy motion.

    Record keys:
        ``kinetic_energy`` (J), or ``link_vel`` ``(n, 3)`` and ``masses`` ``(n,)`` (and
        ``rotational_energy`` J, optional).
    """

    @classmethod
    def needs(cls, params: Any) -> set[str]:
        """``link_vel`` and ``masses`` (what an env records; ``kinetic_energy`` may stand for them)."""
        return {"link_vel", "masses"}

    @dataclasses.dataclass
    class Config:
        mode: str = "decrease"
        """Decrease or increase the energy (002 §3.3)."""
        e_min: float = 20.0
        """J (002 §5.3.1)."""
        e_max: float = 100.0
        """J (002 §5.3.1)."""

        def check(self) -> None:
            from toolkit.schema import finite, require

            require(finite(self.e_min) and finite(self.e_max) and self.e_max > self.e_min, "energy.e_min/e_max",
                    (self.e_min, self.e_max), "finite with e_max > e_min")

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        _mode(self)

    def energy(self, record: dict[str, Any]) -> float:
        if "kinetic_energy" in record:
            return self.scalar(record, "kinetic_energy")
        if "link_vel" not in record:
            raise KeyError(f"reward term {self.term_name} needs record key 'kinetic_energy' (or 'link_vel' and "
                           f"'masses'; record has: {', '.join(sorted(map(str, record))) or 'nothing'})")
        rot = float(record.get("rotational_energy", 0.0) or 0.0)
        return kinetic_energy(self.get(record, "link_vel"), self.get(record, "masses"), rot)

    def __call__(self, record: dict[str, Any]) -> float:
        p = self.params
        e = self.energy(record)
        x = (p.e_max - e) / (p.e_max - p.e_min) if p.mode == "decrease" else (e - p.e_min) / (p.e_max - p.e_min)
        return float(min(max(x, 0.0), 1.0))


class Volume(RecordTerm):
    """Body-volume style reward (002 eq 5): a compact (or an expansive) posture.

    Record keys:
        ``joint_pos`` ``(n, 3)``: the joint positions (m).
    """

    @classmethod
    def needs(cls, params: Any) -> set[str]:
        """``joint_pos``."""
        return {"joint_pos"}

    @dataclasses.dataclass
    class Config:
        mode: str = "decrease"
        """Decrease or increase the volume (002 §3.3)."""
        alpha: float = 0.12
        """M³ (002 §5.3.1)."""

        def check(self) -> None:
            from toolkit.schema import finite, require

            require(finite(self.alpha) and self.alpha > 0, "volume.alpha", self.alpha, "must be > 0")

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        _mode(self)

    def __call__(self, record: dict[str, Any]) -> float:
        v = hull_volume(self.get(record, "joint_pos"))
        r = math.exp(-v / self.params.alpha)
        return float(r if self.params.mode == "decrease" else 1.0 - r)
