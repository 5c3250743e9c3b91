"""``action=cvae``: filtered composite PD targets from the C-VAE (``003`` §3.4–3.5, eq 3).

The policy's action ``a_t = [z', Δq']`` is low-pass filtered, ``y_t = β a_t + (1 - β) y_{t-1}``
with ``β = 0.2`` (``003`` §3.4, after DReCon), and ``y_t = [z, Δq]`` gives the PD target
``DECODER(z, c) + Δq``. The condition ``c = (h, θ_side, θ_front)`` is the task's feature curves
sampled at the current time (``003`` §3.4); give it with ``set_condition(c)`` or as
``obs["condition"]`` / ``obs.condition``. ``reset()`` sets ``y_{-1} = 0`` (the previous filtered
action is part of the paper's state, so it must exist before the first action), or to ``state``
when one is given. ``z`` is in whitened latent units, as for ``action=pvae``.

Naturalness (``003`` eq 3): ``1 - clip((||Δq||_1 / c)^2, 0, 1)`` with the filtered offsets and
``c = 10`` ("a constant value of c = 10 was sufficient").
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

import numpy as np

from jt_actions.base import FilterCheck, naturalness, obs_value
from jt_actions.pvae import PVAEActionSpace
from toolkit.errors import JtError


class CVAEActionSpace(PVAEActionSpace):
    """Action = filtered [C-VAE latent, offsets]; target = decode(latent, c) + offset (003 §3.4)."""

    kind = "cvae"
    needs: ClassVar[frozenset[str]] = frozenset({"condition"})  #: c = the task's curve targets (003 §3.4)

    @dataclasses.dataclass
    class Config(FilterCheck):
        name: str = "cvae"
        prior: str = "auto"
        """Prior.h5 path (or a folder with one), the MLflow run id of a pose_prior run, or "auto":
        the store's own prior, trained on first use from the shipped clips (``toolkit.priors.auto``)."""
        store: str = ""
        """Store to look a run id up in: the run's own store by default."""
        latent_bound: float = 3.0
        """Ours: |z'| bound, in std of the data's latent cloud (whitened latents)."""
        offset_bound: float = 1.0
        """Ours: |dq'| bound per DoF (rad)."""
        beta: float = 0.2
        """003 §3.4: action filter coefficient, y_t = beta a_t + (1 - beta) y_{t-1} (1: no filter)."""
        c: float = 10.0
        """003 eq 3: "a constant value of c = 10 was sufficient"."""
        clip_to_limits: bool = True
        """Targets within the joint limits."""

    def __init__(self, cfg: Any = None, character: Any = None) -> None:
        super().__init__(cfg, character)
        self._condition: np.ndarray | None = None

    def set_condition(self, c: Any) -> None:
        """The C-VAE condition ``(h, θ_side, θ_front)`` ``(3,)`` for the coming steps."""
        c = np.asarray(c, dtype=np.float64).reshape(-1)
        if c.shape != (self.prior.n_cond,):
            raise ValueError(f"the condition has {self.prior.n_cond} entries, got {c.shape[0]}")
        self._condition = c

    @property
    def condition(self) -> np.ndarray | None:
        return self._condition

    def targets(self, action: np.ndarray, obs: Any = None) -> np.ndarray:
        c = obs_value(obs, "condition")
        if c is not None:
            self.set_condition(c)
        if self._condition is None:
            raise JtError("action=cvae needs the condition (h, θ_side, θ_front): call set_condition(c) "
                          "or pass obs={'condition': c}")  # fmt: skip
        z, dq = self.split(self.filter(action))
        self._norms.append(float(np.abs(dq).sum()))
        return self.finish(self.natural_targets(z, self._condition) + dq)

    def reset(self, state: Any = None) -> None:
        """New episode: ``y_{-1} = state`` (``(dim,)``) or zeros; forget the offset norms."""
        super().reset(state)
        self.reset_filter(state)

    def set_c_offset(self, c_offset: float) -> None:
        """The naturalness scale ``c`` of ``003`` eq 3 (constant 10 in the paper)."""
        super().set_c_offset(c_offset)

    def penalty(self) -> float:
        """``003`` eq 3 for the last step's filtered offsets (1 = no offsets)."""
        return naturalness(self.offset_norm(), self.c_offset)
