"""BDS acquisition functions (``000`` §5.1): exploration sigma(x) (eq 9) and expected diversity (eq 7).

Either may be weighted by the probability that a point yields a feature at all
(``jt_searchers.feasibility``; ours, beyond the paper), once a told point has failed.
"""

from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

from jt_searchers.distances import Distance, pairwise
from jt_searchers.gp import FeatureGP


class Exploration:
    """``a_exp(x) = sigma_t(x)``, the posterior standard deviation (``000`` eq 9).

    With a shared kernel every standardised output has the same sigma, so this is one number.

    Args:
        gp: the (possibly fantasised) surrogate.
        feasible: ``p(x)`` model (``Feasibility``) multiplying sigma, or ``None``.
    """

    def __init__(self, gp: FeatureGP, feasible: Optional[Any] = None) -> None:
        self.gp = gp
        self.feasible = feasible

    def __call__(self, U: np.ndarray) -> np.ndarray:
        """Values at unit points ``U`` ``(n, dim)`` → ``(n,)``."""
        std = self.gp.predict_standardised(U)[1]
        return std if self.feasible is None else std * self.feasible(U)

    def value_and_grad(self, u: np.ndarray) -> tuple[float, np.ndarray]:
        """Value and gradient at one unit point ``u`` ``(dim,)`` (for L-BFGS-B)."""
        std, dstd = self.gp.std_and_grad(u)
        if self.feasible is None:
            return std, dstd
        p, dp = self.feasible.value_and_grad(u)
        return std * p, dstd * p + std * dp


class ExpectedDiversity:
    """Monte-Carlo estimate of ``E[min_i d(f_hat, f_i)]``, ``f_hat ~ N(mu_t(x), sigma_t^2(x))`` (eq 7).

    The standard-normal draws ``z`` are fixed when the acquisition is built (common random numbers),
    so the estimate is a deterministic, piecewise-smooth function of ``x`` — DIRECT sees the same
    function on every call, and the same seed gives the same pick.

    Args:
        gp: the (possibly fantasised) surrogate.
        observed: features already observed ``(t, m)``, raw units (fantasised ones included in a batch).
        distance: vectorised feature distance (``distances``).
        z: standard-normal draws ``(n_mc, m)``.
        feasible: ``p(x)`` model (``Feasibility``) multiplying the estimate, or ``None``.
    """

    def __init__(self, gp: FeatureGP, observed: np.ndarray, distance: Distance, z: np.ndarray,
                 feasible: Optional[Any] = None) -> None:
        self.gp = gp
        self.feasible = feasible
        self.observed = np.asarray(observed, dtype=float).reshape(-1, len(gp.centre))
        self.distance = distance
        self.z = np.asarray(z, dtype=float)

    def __call__(self, U: np.ndarray) -> np.ndarray:
        """Values at unit points ``U`` ``(n, dim)`` → ``(n,)``."""
        U = np.asarray(U, dtype=float).reshape(-1, self.gp.dim)
        mean, std = self.gp.predict(U)  # (n, m), (n, m)
        if len(self.observed) == 0:
            return np.zeros(len(U))
        out = np.empty(len(U))
        for i in range(len(U)):
            samples = mean[i] + std[i] * self.z  # (n_mc, m)
            out[i] = np.mean(np.min(pairwise(self.distance, samples, self.observed), axis=1))
        return out if self.feasible is None else out * self.feasible(U)

    def scalar(self) -> Callable[[np.ndarray], float]:
        """``x (dim,) -> float`` for optimisers that take one point at a time (DIRECT)."""
        return lambda u: float(self(np.asarray(u)[None])[0])
