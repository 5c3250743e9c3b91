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
"""

from __future__ import annotations

from typing import Optional

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
