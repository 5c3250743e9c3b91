"""Acquisition optimisers over the unit cube: multi-start L-BFGS-B and DIRECT (``000`` Alg. 1 lines 5, 7)."""

from __future__ import annotations

from typing import Callable

import numpy as np


def maximize_lbfgsb(
    value_and_grad: Callable[[np.ndarray], tuple[float, np.ndarray]],
    starts: np.ndarray,
    maxiter: int = 200,
) -> tuple[np.ndarray, float]:
    """Maximise a smooth function over ``[0, 1]^dim`` with L-BFGS-B from each start.

    Args:
        value_and_grad: ``u (dim,) -> (value, gradient (dim,))``.
        starts: start points ``(k, dim)``; the best local optimum wins (first on ties).
        maxiter: L-BFGS-B iteration cap per start.

    Returns:
        The best point ``(dim,)`` and its value.
    """
    from scipy.optimize import minimize

    def neg(u: np.ndarray) -> tuple[float, np.ndarray]:
        v, g = value_and_grad(u)
        return -float(v), -np.asarray(g, dtype=float)

    starts = np.atleast_2d(starts)
    bounds = [(0.0, 1.0)] * starts.shape[1]
    best_u, best_v = None, -np.inf
    for s in starts:
        res = minimize(neg, np.clip(s, 0.0, 1.0), jac=True, method="L-BFGS-B", bounds=bounds,
                       options={"maxiter": maxiter})
        u = np.clip(res.x, 0.0, 1.0)
        v = -neg(u)[0]
        if v > best_v + 1e-12:
            best_u, best_v = u, v
    return best_u, best_v


def maximize_direct(
    fun: Callable[[np.ndarray], float], dim: int, maxfun: int = 2000
) -> tuple[np.ndarray, float]:
    """Maximise ``fun`` over ``[0, 1]^dim`` with DIRECT (Jones et al.; ``scipy.optimize.direct``).

    The original, not locally biased, variant is used (``000`` cites Jones 2001). DIRECT is
    deterministic, so the pick depends only on ``fun``.

    Args:
        fun: ``u (dim,) -> float``.
        dim: dimension.
        maxfun: evaluation budget of DIRECT.

    Returns:
        The best point ``(dim,)`` and its value.
    """
    from scipy.optimize import direct

    res = direct(lambda u: -fun(u), [(0.0, 1.0)] * dim, maxfun=maxfun, locally_biased=False,
                 maxiter=max(1000, maxfun))
    u = np.clip(np.asarray(res.x, dtype=float), 0.0, 1.0)
    return u, -float(res.fun)
