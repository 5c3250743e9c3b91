"""Probability that an evaluation yields a feature, for BDS's acquisitions (ours, beyond ``000``).

``000`` Alg. 1 tells BDS every sample's feature; it is silent on samples that yield none (a jump
that never crosses the bar). Kriging-believing such a point only lowers the posterior std *at* it:
its neighbourhood keeps the GP's extrapolated features, which the diversity term (eq 7) can still
find attractive, and a laptop run re-sampled one failed corner three times. The usual remedy in
constrained Bayesian optimisation (Gelbart, Snoek & Adams 2014; Gardner et al. 2014) is to weight
the acquisition by the probability of feasibility under a second GP: here a GP on labels
``+1`` (a feature) / ``-1`` (none) over the told points, with the feature GP's length scales, and

    p(x) = Phi(mu(x) / sigma(x))

so a failed point's neighbourhood (mu ~ -1, sigma small) gets p ~ 0, unexplored space p = 1/2 and
the neighbourhood of successes p -> 1.

A *known* constraint of the problem (``SearchProblem.constraint``, e.g. the high jump's take-off
states whose run-up cannot reach the bar plane in flight) is no probability: ``KnownConstraint``
weighs infeasible points 0, feasible ones 1, and ``combine`` multiplies it with the learned model.
"""

from __future__ import annotations

from typing import Any, Optional

import numpy as np
from scipy.stats import norm

from jt_searchers.gp import FeatureGP, matern52_grad

#: label variance the feasibility GP assumes (labels are +-1)
AMPLITUDE = 1.0
#: observation noise variance of the labels (nearly noise-free: a told outcome is a fact)
NOISE = 1e-2


class Feasibility:
    """GP classifier-by-regression of "this point yields a feature".

    Args:
        U: told unit points ``(t, dim)``.
        ok: whether each gave a feature ``(t,)``.
        lengthscales: ARD length scales ``(dim,)`` (the feature GP's).
    """

    def __init__(self, U: np.ndarray, ok: np.ndarray, lengthscales: np.ndarray) -> None:
        U = np.asarray(U, dtype=float)
        dim = U.shape[1]
        labels = np.where(np.asarray(ok, bool), 1.0, -1.0)[:, None]
        self.gp = FeatureGP(dim, [0.0], [1.0], lengthscales, AMPLITUDE, NOISE).condition(U, labels)

    def __call__(self, U: np.ndarray) -> np.ndarray:
        """``p(x)`` at unit points ``U`` ``(n, dim)`` → ``(n,)``."""
        mean, std = self.gp.predict_standardised(U)
        return norm.cdf(mean[:, 0] / std)

    def value_and_grad(self, u: np.ndarray) -> tuple[float, np.ndarray]:
        """``p`` and its gradient ``(dim,)`` at one unit point ``u`` ``(dim,)``."""
        gp = self.gp
        u = np.asarray(u, dtype=float).reshape(gp.dim)
        mean = float(gp.predict_standardised(u[None])[0][0, 0])
        std, dstd = gp.std_and_grad(u)
        dk = matern52_grad(u, gp.U, gp.lengthscales, gp.amplitude)  # (t, dim)
        dmean = gp._alpha[:, 0] @ dk
        r = mean / std
        return float(norm.cdf(r)), norm.pdf(r) * (dmean * std - mean * dstd) / std**2


def feasibility(U: np.ndarray, ok: np.ndarray, lengthscales: np.ndarray) -> Optional[Feasibility]:
    """The model when at least one told point failed, else ``None`` (Alg. 1 unchanged)."""
    ok = np.asarray(ok, bool)
    if ok.all():
        return None
    return Feasibility(U, ok, lengthscales)


class KnownConstraint:
    """Indicator of ``SearchProblem.constraint`` on unit points (1 feasible, 0 not; gradient 0).

    Args:
        problem: the search problem (its ``constraint``).
        box: the unit-cube map of its space.
    """

    def __init__(self, problem: Any, box: Any) -> None:
        self.problem, self.box = problem, box

    def __call__(self, U: np.ndarray) -> np.ndarray:
        """``1[x feasible]`` at unit points ``U`` ``(n, dim)`` → ``(n,)``."""
        from jt_searchers.base import feasible_mask

        return feasible_mask(self.problem, self.box, U).astype(float)

    def value_and_grad(self, u: np.ndarray) -> tuple[float, np.ndarray]:
        """The indicator at one unit point ``u`` ``(dim,)`` and a zero gradient ``(dim,)``."""
        u = np.asarray(u, dtype=float).reshape(-1)
        return float(self(u[None])[0]), np.zeros_like(u)


class Product:
    """Product of weight models (``Feasibility``, ``KnownConstraint``) with the same interface.

    Args:
        *models: the models; ``None`` entries are skipped.
    """

    def __init__(self, *models: Any) -> None:
        self.models = [m for m in models if m is not None]

    def __call__(self, U: np.ndarray) -> np.ndarray:
        """Product of the models at unit points ``U`` ``(n, dim)`` → ``(n,)``."""
        out = np.ones(len(np.atleast_2d(U)))
        for m in self.models:
            out = out * m(U)
        return out

    def value_and_grad(self, u: np.ndarray) -> tuple[float, np.ndarray]:
        """Product and its gradient ``(dim,)`` at one unit point ``u`` ``(dim,)`` (product rule)."""
        parts = [m.value_and_grad(u) for m in self.models]
        value = float(np.prod([v for v, _ in parts]))
        grad = np.zeros(len(np.asarray(u).reshape(-1)))
        for i, (_, g) in enumerate(parts):
            grad = grad + np.asarray(g) * float(np.prod([v for j, (v, _) in enumerate(parts) if j != i]))
        return value, grad


def combine(*models: Any) -> Any:
    """The product of the models that are not ``None``: ``None`` when none is, the model itself when one is."""
    kept = [m for m in models if m is not None]
    if not kept:
        return None
    return kept[0] if len(kept) == 1 else Product(*kept)
