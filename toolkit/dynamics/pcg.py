"""Jacobi-preconditioned conjugate gradient for ``A x = b`` (the PCG method of thesis §2.4.2).

``A = M + Kd dt`` is symmetric positive definite but small and dense, so PCG needs up to ~n
iterations of an O(n^2) product: no faster than factorising (as the thesis found). Convergence is
checked on the true residual, recomputed whenever the recursive one says "converged", so the
answer meets the tolerance in floating point rather than only in the recursion.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _matvec(A: np.ndarray, x: np.ndarray, out: np.ndarray) -> None:
    n = A.shape[0]
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += A[i, j] * x[j]
        out[i] = s


@njit(cache=True)
def pcg_solve(A: np.ndarray, b: np.ndarray, x: np.ndarray, r: np.ndarray, z: np.ndarray,
              p: np.ndarray, Ap: np.ndarray, pre: np.ndarray, tol: float, max_iter: int) -> int:
    """Solve ``A x = b`` from ``x = 0``; returns the number of iterations.

    Args:
        A: SPD matrix ``(n, n)``.
        b: right-hand side ``(n,)``.
        x: solution (output) ``(n,)``.
        r, z, p, Ap, pre: work vectors ``(n,)``.
        tol: stop when ``||b - A x||_2 <= tol * ||b||_2``.
        max_iter: iteration cap.
    """
    n = A.shape[0]
    bn = 0.0
    for i in range(n):
        pre[i] = 1.0 / A[i, i]
        x[i] = 0.0
        r[i] = b[i]
        bn += b[i] * b[i]
    bn = math.sqrt(bn)
    if bn == 0.0:
        return 0
    it = 0
    restart = True
    rz = 0.0
    while it < max_iter:
        if restart:
            rz = 0.0
            for i in range(n):
                z[i] = pre[i] * r[i]
                p[i] = z[i]
                rz += r[i] * z[i]
            restart = False
        _matvec(A, p, Ap)
        pAp = 0.0
        for i in range(n):
            pAp += p[i] * Ap[i]
        alpha = rz / pAp
        rn = 0.0
        for i in range(n):
            x[i] += alpha * p[i]
            r[i] -= alpha * Ap[i]
            rn += r[i] * r[i]
        it += 1
        if math.sqrt(rn) <= tol * bn:
            # verify with the true residual; restart the recursion from it if not yet there
            _matvec(A, x, Ap)
            rn = 0.0
            for i in range(n):
                r[i] = b[i] - Ap[i]
                rn += r[i] * r[i]
            if math.sqrt(rn) <= tol * bn:
                return it
            restart = True
            continue
        rz_new = 0.0
        for i in range(n):
            z[i] = pre[i] * r[i]
            rz_new += r[i] * z[i]
        beta = rz_new / rz
        rz = rz_new
        for i in range(n):
            p[i] = z[i] + beta * p[i]
    return it
