"""Searchers: ask/tell over a box of named parameters (``jt.searchers``)."""

from __future__ import annotations

import abc
import dataclasses
from typing import TYPE_CHECKING, Any, Callable, ClassVar, Optional, Sequence

from toolkit.interfaces.plugin import Plugin

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np

    from toolkit.interfaces.task import Evaluation


@dataclasses.dataclass(frozen=True)
class Param:
    """One searchable parameter.

    Attributes:
        name: parameter name, as the task's ``evaluate`` receives it.
        low: lower bound (inclusive).
        high: upper bound (inclusive).
        default: value used by ``search=single`` when none is given.
    """

    name: str
    low: float
    high: float
    default: Optional[float] = None


@dataclasses.dataclass(frozen=True)
class Space:
    """A box of named parameters.

    Attributes:
        params: the parameters, in the order of the point vectors searchers exchange.
    """

    params: tuple[Param, ...]

    @property
    def dim(self) -> int:
        return len(self.params)

    @property
    def names(self) -> list[str]:
        return [p.name for p in self.params]

    @property
    def lows(self) -> list[float]:
        return [float(p.low) for p in self.params]

    @property
    def highs(self) -> list[float]:
        return [float(p.high) for p in self.params]

    def to_dict(self, x: Sequence[float]) -> dict[str, float]:
        """Point vector ``(dim,)`` → ``{name: value}``."""
        return {p.name: float(v) for p, v in zip(self.params, x)}

    def defaults(self) -> list[float]:
        """Default point: each parameter's default, or the centre of its range."""
        return [p.default if p.default is not None else 0.5 * (p.low + p.high) for p in self.params]


@dataclasses.dataclass
class SearchProblem:
    """What a task tells a searcher about its outer problem.

    Attributes:
        space: the box to search.
        n_features: size of the strategy feature vector an evaluation returns (BDS), 0 if none.
        feature_low: lower end of each feature's range ``(n_features,)``; the GP prior mean is the
            centre of the range (``000`` §5.1).
        feature_high: upper end of each feature's range ``(n_features,)``.
        feature_distance: distance between two feature vectors; ``None`` means Euclidean. Tasks
            with angles or rotations supply their own (wrap-around, quaternion sign).
        n_objectives: number of objectives an evaluation returns (RMOO/BSOO), all minimised.
        objective_names: names of the objectives, for tables and plots.
        reference_point: hypervolume reference point ``(n_objectives,)`` (worse than any sample).
        distinct_threshold: two features closer than this count as the same strategy.
        constraint: a known constraint on the box, ``X (n, dim) -> margins (n,)``: a point is
            feasible where its margin is >= 0 (e.g. the high jump's take-off states whose run-up
            reaches the bar plane in flight). Searchers with ``honours_constraint`` keep to it
            (``search=single`` by evaluating only the one point it is given); the others refuse a
            constrained problem. ``None``: the whole box.
        constraint_name: what the constraint is, for messages (e.g. ``task.max_time_to_bar=0.5``).
    """

    space: Space
    n_features: int = 0
    feature_low: Optional[Sequence[float]] = None
    feature_high: Optional[Sequence[float]] = None
    feature_distance: Optional[Callable[[Any, Any], float]] = None
    n_objectives: int = 0
    objective_names: Sequence[str] = ()
    reference_point: Optional[Sequence[float]] = None
    distinct_threshold: Optional[float] = None
    constraint: Optional[Callable[[Any], Any]] = None
    constraint_name: str = ""


class Searcher(Plugin, abc.ABC):
    """Ask/tell optimiser or explorer over a ``SearchProblem``'s box.

    The runner calls ``ask(n)`` for up to ``n`` points (a batch evaluated in parallel), evaluates
    them, and calls ``tell`` with the results, until ``finished()``. Searchers must be
    deterministic given ``seed`` and the sequence of tells: the runner resumes an interrupted
    search by constructing the searcher anew and replaying the recorded history through
    ``ask``/``tell`` (the recorded evaluations stand in for re-running them).

    Required: ``ask``, ``tell``, ``finished`` and a ``Config`` with ``name`` and ``budget`` (the
    most evaluations the runner makes). Optional, with defaults: ``batch_size`` (from the Config's
    ``batch`` when it has one, else 1), ``nested`` (True), ``summary()`` (empty).

    Attributes:
        nested: True (default): each evaluation is a nested MLflow run under the outer run;
            False: the one evaluation is logged on the outer run itself (``search=single``).
        honours_constraint: True when the searcher proposes only points within
            ``SearchProblem.constraint`` (``search=single``: it proposes nothing, it evaluates
            the point it is given); a searcher that does not (the default) refuses a constrained
            problem in one line rather than silently sampling outside it.

    Args:
        problem: what to search.
        cfg: the ``search`` config group, validated against ``Config``.
        seed: the run's seed.
    """

    nested: ClassVar[bool] = True
    honours_constraint: ClassVar[bool] = False

    def __init__(self, problem: SearchProblem, cfg: Any, seed: int) -> None:
        if problem.constraint is not None and not type(self).honours_constraint:
            from toolkit.errors import JtError

            name = getattr(type(self), "name", "") or type(self).__name__
            able = ", ".join(f"search={n}" for n in _honouring_searchers()) or "none installed"
            raise JtError(f"search={name} cannot keep to the task's constraint "
                          f"({problem.constraint_name or 'SearchProblem.constraint'}): unset it or use a searcher "
                          f"that honours it ({able})")
        self.problem = problem
        self.cfg = cfg
        self.seed = seed

    @property
    def batch_size(self) -> int:
        """Points the runner asks for at once (and evaluates in parallel): the config's ``batch``
        when the ``Config`` has one, else 1 -- a searcher that says nothing about batches is asked
        one point at a time. Override it for another rule."""
        cfg = self.cfg
        if cfg is None:
            return 1
        if isinstance(cfg, dict) or hasattr(cfg, "keys"):  # a dict or a config node
            value = cfg["batch"] if "batch" in cfg else None
        else:  # a typed Config instance
            value = getattr(cfg, "batch", None)
        return 1 if value is None else int(value)

    @abc.abstractmethod
    def ask(self, n: int) -> "np.ndarray":
        """Next points to evaluate, shape ``(k, dim)`` with ``1 <= k <= n`` (``k = 0`` when done)."""

    @abc.abstractmethod
    def tell(self, points: "np.ndarray", results: Sequence["Evaluation"]) -> None:
        """Results for points previously asked, ``points`` of shape ``(k, dim)``."""

    @abc.abstractmethod
    def finished(self) -> bool:
        """True when the budget is spent or the search has converged."""

    def summary(self) -> dict[str, Any]:
        """Arrays describing the search state (GP data, fronts, ...) for the outer run's HDF5."""
        return {}


def _honouring_searchers() -> list[str]:
    """The installed searchers that keep to a task's constraint (``honours_constraint``)."""
    from toolkit import plugins
    from toolkit.errors import JtError

    out = []
    for name in plugins.names("search"):
        try:
            if getattr(plugins.load("search", name), "honours_constraint", False):
                out.append(name)
        except JtError:  # a broken plugin is reported where it is used
            continue
    return out
