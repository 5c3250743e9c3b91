"""Action spaces (``jt.actions``): policy output ↔ PD targets."""

from __future__ import annotations

import abc
from typing import TYPE_CHECKING, Any, ClassVar

from toolkit.interfaces.plugin import GroupPlugin

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np


class ActionSpace(GroupPlugin, abc.ABC):
    """Maps a policy's action vector to PD targets, once per control step.

    Required: ``dim``, ``bounds``, ``reset``, ``targets``. Optional, with defaults: ``penalty``
    (1.0), ``anchor`` (ignored), ``skeleton`` (None), ``filtered`` (None). Tasks also call these
    hooks when an action space has them (looked up with ``hasattr``, so there is no default):
    ``set_phase(phase)`` (the reference clip's phase this control step, ``task=spacetime``),
    ``set_condition(c)`` (a C-VAE's condition, ``task=getup``), ``set_c_offset(value)`` and the
    attribute ``c_offset`` (a P-VAE's offset scale that a curriculum anneals, the jump tasks).

    Attributes:
        skeleton: the skeleton the targets are for (``toolkit.motion``: joint order, limits);
            the policy tasks read it, so an action space used by them sets it. None by default.
        filtered: the action after the space's own filter (the previous step's, fed back into
            ``task=getup``'s observation), or None (default: the task uses the raw action).

    Args:
        cfg: the ``action`` config group, validated against ``Config``.
        character: the character description the targets are for.
    """

    what: ClassVar[str] = "action={name}"
    #: what it needs from the task's environment besides the action: ``"condition"``
    #: (``set_condition``), ``"phase"`` (``set_phase``); checked at composition against
    #: ``Task.action_inputs`` where a task declares them
    needs: ClassVar[frozenset[str]] = frozenset()
    #: True for a space that decodes through a trained prior (``action.prior``): a task checks
    #: one is named before a run opens, and ``jt bench rollout`` swaps in ``action=raw`` for it
    needs_prior: ClassVar[bool] = False

    skeleton: Any = None
    filtered: Any = None

    def __init__(self, cfg: Any, character: Any = None) -> None:
        self.character = character
        super().__init__(cfg)

    @property
    @abc.abstractmethod
    def dim(self) -> int:
        """Size of the action vector."""

    @abc.abstractmethod
    def bounds(self) -> tuple["np.ndarray", "np.ndarray"]:
        """Lower and upper bounds ``(dim,)`` of the action vector."""

    @abc.abstractmethod
    def reset(self, state: Any = None) -> None:
        """Start of an episode (clears filters)."""

    @abc.abstractmethod
    def targets(self, action: "np.ndarray", obs: Any = None) -> "np.ndarray":
        """PD targets for the character's internal joints from ``action`` ``(dim,)``."""

    @classmethod
    def prior_run(cls, action: Any) -> "list[str] | None":
        """The ``jt run`` overrides that train this action space's prior when its ``action``
        config asks for the store's own one (``action.prior=auto``, ``toolkit.priors.auto``), or
        None: nothing to train first (the default)."""
        return None

    def penalty(self) -> float:
        """The action space's own reward term for the last step (1.0 = no penalty)."""
        return 1.0

    def anchor(self, q: "np.ndarray") -> None:
        """The episode's initial configuration ``(n_q,)``, given after every reset (for action
        spaces relative to it); ignored by default."""
