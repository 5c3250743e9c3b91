"""The Stage-2 novelty reward of ``000`` eq 12 (thesis ``001`` eq 3.12)."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from jt_rewards.base import RecordTerm
from jt_rewards.distances import resolve
from toolkit.errors import JtError


class Novelty(RecordTerm):
    """r_novelty = clip(min_i d(f, f_i) / d_threshold, 0.01, 1), d_threshold = π/2 (000 eq 12).

    ``f`` is this episode's strategy feature and ``f_i`` those of the previously found policies
    (``000`` §5.2). With no previous policy the minimum over the empty set is +∞, so the term is 1
    and Stage 2 reduces to the Stage-1 reward (eq 15 = eq 2).

    Record keys:
        ``feature`` (``(d,)``): the episode's strategy feature (``000`` §6.1.4: the root
        orientation when the CoM crosses the bar plane).
        ``policy_features`` (``(n, d)``, optional): features of the previous policies; when the
        record lacks it (or it is None) the config's ``policy_features`` are used.
    """

    @dataclasses.dataclass
    class Config:
        d_threshold: float = math.pi / 2  # desired novelty distance (000 §6.2, eq 12: π/2)
        low: float = 0.01  # lower clip bound (000 eq 12)
        high: float = 1.0  # upper clip bound (000 eq 12)
        distance: str = "euclidean"  # euclidean | angle | quat | rotvec (eq 12 writes ‖f_i − f‖)
        policy_features: list = dataclasses.field(default_factory=list)  # f_i, used if the record has none
        key: str = "feature"  # record key of this episode's feature f
        policies_key: str = "policy_features"  # record key of the previous policies' features

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        p = self.params
        if not p.d_threshold > 0:
            raise JtError(f"novelty: d_threshold must be > 0, got {p.d_threshold}")
        if not 0 <= p.low <= p.high:
            raise JtError(f"novelty: need 0 <= low <= high, got {p.low}, {p.high}")
        self.distance = resolve(p.distance)

    def min_distance(self, feature: Any, policy_features: Any) -> float:
        """``min_i d(f, f_i)``; ``inf`` for an empty set.

        Args:
            feature: ``f`` ``(d,)``.
            policy_features: ``(n, d)`` (or a list of ``n`` features), ``n`` may be 0.
        """
        f = np.asarray(feature, dtype=np.float64).reshape(-1)
        others = np.asarray(policy_features, dtype=np.float64)
        if others.size == 0:
            return math.inf
        others = others.reshape(-1, f.shape[0]) if others.ndim == 1 else others
        if others.ndim != 2 or others.shape[1] != f.shape[0]:
            raise ValueError(f"novelty: feature {f.shape} and policy features {others.shape} disagree")
        if not (np.all(np.isfinite(f)) and np.all(np.isfinite(others))):
            raise ValueError("novelty: non-finite feature")
        return float(np.min(self.distance(f, others)))

    def __call__(self, record: dict[str, Any]) -> float:
        p = self.params
        feature = self.get(record, p.key)
        others = record.get(p.policies_key)
        if others is None:
            others = p.policy_features
        d = self.min_distance(feature, others)
        return float(min(max(d / p.d_threshold, p.low), p.high))
