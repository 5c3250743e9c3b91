"""``action=pvae``: composite PD targets from the P-VAE (``000`` §4.2, thesis ``001`` §3.4.2).

The action is ``a = (a_latent, a_offset)``, ``d_latent + d_offset`` wide with offsets on every
internal DoF ("we simply apply offsets to all internal joints"); the PD target is
``D_pose(a_latent) + a_offset`` in exp maps / angles. ``a_latent`` is in whitened units of the
prior's latent cloud (``z = z_mean + z_std * a_latent``, see ``toolkit.priors.model``), so 0 is
the centre of the natural poses and the bounds are a number of standard deviations.

Naturalness (``000`` eq 4): ``1 - clip((||a_offset||_1 / c_offset)^2, 0, 1)``, returned by
``penalty()``; with ``episode_average`` the norm is the mean over the episode so far (the paper's
choice for sparse-reward tasks). ``c_offset`` follows ``000`` §6.1.2's schedule
``48 - 33 clip(rho, 0, 1)`` when a curriculum calls ``set_c_offset``.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from jt_actions.base import DofActionSpace, FilterCheck, naturalness
from toolkit.errors import JtError


class PVAEActionSpace(DofActionSpace):
    """Action = [P-VAE latent, per-DoF offsets]; target = decode(latent) + offset (000 §4.2)."""

    kind = "pvae"
    needs_prior = True

    @dataclasses.dataclass
    class Config(FilterCheck):
        name: str = "pvae"
        beta: float = 1.0
        """Action filter y_t = beta a_t + (1 - beta) y_{t-1} (003 §3.4's, an option of every action
        space); 1: no filter (the papers' choice for this space)."""
        prior: str = "auto"
        """Prior.h5 path (or a folder with one), the MLflow run id of a pose_prior run, or "auto":
        the store's own prior, trained on first use from the shipped clips (``toolkit.priors.auto``)."""
        store: str = ""
        """Store to look a run id up in: the run's own store by default."""
        latent_bound: float = 3.0
        """Ours: |a_latent| bound, in std of the data's latent cloud (whitened latents)."""
        offset_bound: float = 1.0
        """Ours: |a_offset| bound per DoF (rad); offsets on all internal DoFs (000 §4.2)."""
        c_offset: float = 15.0
        """000 eq 4 / §6.1.2: c_offset = 48 - 33 clip(rho, 0, 1) -> 15 at rho >= 1 (curriculum sets it)."""
        episode_average: bool = False
        """000 §4.2: sparse-reward tasks use the episode mean of ||a_offset||_1."""
        clip_to_limits: bool = True
        """Targets within the joint limits."""

    @classmethod
    def prior_run(cls, action: Any) -> list[str] | None:
        """With ``prior: auto``: ``task=pose_prior action=<this space>`` trains its prior."""
        if str(action.get("prior", "")).strip() != "auto":
            return None
        return ["task=pose_prior", f"action={cls.kind}"]

    def __init__(self, cfg: Any = None, character: Any = None) -> None:
        super().__init__(cfg, character)
        from toolkit.priors.io import load_prior

        self.prior = load_prior(self.params.prior, self.params.store or None, kind=self.kind)
        if self.prior.layout.skeleton != self.skeleton.name:
            raise JtError(f"action={self.kind}: the prior is for the {self.prior.layout.skeleton}, "
                          f"the character is the {self.skeleton.name}")  # fmt: skip
        self.c_offset = float(getattr(self.params, "c_offset", getattr(self.params, "c", 1.0)))
        self._norms: list[float] = []

    # ---- layout --------------------------------------------------------------------------------
    @property
    def latent_dim(self) -> int:
        return self.prior.latent_dim

    @property
    def dim(self) -> int:
        return self.latent_dim + self.n_dof

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        p = self.params
        high = np.concatenate([np.full(self.latent_dim, p.latent_bound), np.full(self.n_dof, p.offset_bound)])
        return -high, high

    def split(self, action: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(a_latent (latent_dim,), a_offset (n_dof,))`` of an action."""
        a = np.asarray(action, dtype=np.float64)
        return a[..., : self.latent_dim], a[..., self.latent_dim :]

    # ---- control -------------------------------------------------------------------------------
    def natural_targets(self, a_latent: np.ndarray, condition: Any = None) -> np.ndarray:
        """``D_pose(a_latent)`` ``(n_dof,)``: the decoded natural pose, before offsets."""
        return self.prior.decode_targets(self.prior.latent_from_action(a_latent), condition)

    def targets(self, action: np.ndarray, obs: Any = None) -> np.ndarray:
        a_lat, a_off = self.split(self.filter(action))
        self._norms.append(float(np.abs(a_off).sum()))
        return self.finish(self.natural_targets(a_lat) + a_off)

    def reset(self, state: Any = None) -> None:
        """New episode: forget the offset norms; the filter starts from zero."""
        self._norms = []
        self.reset_filter(None)

    # ---- naturalness ---------------------------------------------------------------------------
    def set_c_offset(self, c_offset: float) -> None:
        """Maximum offset allowed (a curriculum schedules it, ``000`` §6.1.2)."""
        if c_offset <= 0:
            raise ValueError(f"c_offset must be positive, got {c_offset}")
        self.c_offset = float(c_offset)

    def offset_norm(self) -> float:
        """``||a_offset||_1`` of the last step, or its episode mean with ``episode_average``."""
        if not self._norms:
            return 0.0
        return float(np.mean(self._norms)) if getattr(self.params, "episode_average", False) else self._norms[-1]

    def penalty(self) -> float:
        """``000`` eq 4 for the last step (1 = no offsets)."""
        return naturalness(self.offset_norm(), self.c_offset)
