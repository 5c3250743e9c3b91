"""What jt's action spaces share: config parsing, the character's dof layout and joint limits.

PD targets are in the dof layout of ``toolkit.motion.skeletons`` (``Skeleton.dof_slices``: an
exponential map per spherical joint, an angle per revolute joint; 28 wide for the humanoid, in
``HUMANOID.dofs`` order). Targets leave every action space within ``toolkit.priors.limits``'
joint limits (canonical exp maps, revolute angles clipped to the URDF range) unless a config sets
``clip_to_limits: false``.

Nothing heavy is imported at module level (``jt plugins`` imports plugin modules to list them).
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from toolkit.errors import JtError
from toolkit.interfaces.action import ActionSpace


def skeleton_of(character: Any) -> Any:
    """The ``Skeleton`` an action space targets: ``character`` itself, its ``.skeleton``, a
    skeleton name, or the DeepMimic ``HUMANOID`` when ``None``."""
    from toolkit.motion.skeletons import HUMANOID, SKELETONS, Skeleton

    if character is None:
        return HUMANOID
    if isinstance(character, Skeleton):
        return character
    if isinstance(character, str):
        if character not in SKELETONS:
            raise JtError(f"unknown character '{character}'; choose one of: {', '.join(SKELETONS)}")
        return SKELETONS[character]
    inner = getattr(character, "skeleton", None)
    if isinstance(inner, Skeleton):
        return inner
    raise JtError(f"an action space needs a toolkit.motion Skeleton, got {type(character).__name__}")


def obs_value(obs: Any, key: str) -> Any:
    """``obs[key]`` for a mapping, ``obs.key`` for an object, else ``None``."""
    if obs is None:
        return None
    if isinstance(obs, Mapping):
        return obs.get(key)
    return getattr(obs, key, None)


class FilterCheck:
    """Mixin of every built-in action space's ``Config``: ``beta`` in (0, 1], checked at composition."""

    def check(self) -> None:
        from toolkit.schema import require

        beta = getattr(self, "beta", 1.0)
        require(isinstance(beta, (int, float)) and 0.0 < float(beta) <= 1.0, "action.beta", beta,
                "a filter coefficient in (0, 1] (1: no filter)")


class DofActionSpace(ActionSpace):
    """Base of jt's action spaces: PD targets in the character's dof layout, within joint limits.

    Args:
        cfg: the ``action`` config group (dict, OmegaConf node or ``Config``); ``None`` = defaults.
        character: a ``Skeleton`` (``HUMANOID`` when ``None``).

    Attributes:
        params: the parsed ``Config``.
        skeleton: the character's joint table.
    """

    def __init__(self, cfg: Any = None, character: Any = None) -> None:
        skeleton = skeleton_of(character)
        super().__init__(cfg, skeleton)  # the interface validates cfg into self.params (one line on a mistake)
        self.skeleton = skeleton
        beta = getattr(self.params, "beta", 1.0)
        if not 0.0 < float(beta) <= 1.0:
            raise JtError(f"action={self.params.name}: beta must be in (0, 1] (1: no filter), got {beta}")
        self._y: np.ndarray | None = None

    # ---- the action filter (003 §3.4, after DReCon): an option of every action space -------------
    @property
    def beta(self) -> float:
        """Filter coefficient: ``y_t = β a_t + (1 - β) y_{t-1}``; 1 is no filter."""
        return float(getattr(self.params, "beta", 1.0))

    @property
    def filtered(self) -> np.ndarray | None:
        """The filtered action ``y_{t-1}`` ``(dim,)`` (part of the get-up policy's observation,
        ``003`` §3.3), or None without a filter (β = 1: the task uses the action itself)."""
        if self.beta == 1.0:
            return None
        return np.zeros(self.dim) if self._y is None else self._y.copy()

    def filter(self, action: np.ndarray) -> np.ndarray:
        """Advance the filter with ``action`` ``(dim,)``; returns ``y_t`` (``action`` itself, as a
        float array, when β = 1)."""
        a = self.check_action(action)
        b = self.beta
        if b == 1.0:
            return a
        prev = np.zeros(self.dim) if self._y is None else self._y
        self._y = b * a + (1.0 - b) * prev
        return self._y.copy()

    def reset_filter(self, state: Any = None) -> None:
        """New episode: ``y_{-1} = state`` ``(dim,)``, or zeros."""
        self._y = None if state is None else self.check_action(state).copy()

    @property
    def n_dof(self) -> int:
        """Number of PD targets (28 for the humanoid)."""
        return self.skeleton.n_dof

    def joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Target limits ``(n_dof,)`` (see ``toolkit.priors.limits``)."""
        from toolkit.priors.limits import joint_limits

        return joint_limits(self.skeleton)

    def finish(self, dofs: np.ndarray) -> np.ndarray:
        """Final targets ``(n_dof,)``: within the joint limits when ``clip_to_limits`` is on."""
        from toolkit.priors.limits import limit_targets

        if getattr(self.params, "clip_to_limits", True):
            return limit_targets(self.skeleton, dofs)
        return np.asarray(dofs, dtype=np.float64)

    def check_action(self, action: Any) -> np.ndarray:
        """``action`` as a float array ``(dim,)``; a wrong size is a ``ValueError``."""
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        if a.shape != (self.dim,):
            raise ValueError(f"{type(self).__name__} takes actions of size {self.dim}, got {a.shape[0]}")
        return a


def naturalness(norm_l1: float, c: float) -> float:
    """``1 - clip((norm_l1 / c)^2, 0, 1)``: ``000`` eq 4 and ``003`` eq 3."""
    if c <= 0:
        raise ValueError(f"the offset scale c must be positive, got {c}")
    return float(1.0 - np.clip((norm_l1 / c) ** 2, 0.0, 1.0))
