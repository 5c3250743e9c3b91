"""Dense Cholesky ``A = L L^T`` and solve: the DF method of thesis §2.2.3 (O(n^3)).

Written as plain loops so it runs inside numba kernels without allocating; for the matrix sizes
here (n <= ~200) it is within a small factor of LAPACK ``dpotrf`` and avoids its call overhead.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def chol_factor(A: np.ndarray) -> None:
    """In-place lower Cholesky factor of the SPD matrix ``A`` ``(n, n)`` (lower triangle)."""
    n = A.shape[0]
    for j in range(n):
        s = A[j, j]
        for k in range(j):
            s -= A[j, k] * A[j, k]
        d = math.sqrt(s)
        A[j, j] = d
        inv = 1.0 / d
        for i in range(j + 1, n):
            s = A[i, j]
            for k in range(j):
                s -= A[i, k] * A[j, k]
            A[i, j] = s * inv


@njit(cache=True)
def chol_solve(L: np.ndarray, b: np.ndarray, x: np.ndarray) -> None:
    """Solve ``L L^T x = b`` with the factor from ``chol_factor``."""
    n = L.shape[0]
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= L[i, k] * x[k]
        x[i] = s / L[i, i]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, n):
            s -= L[k, i] * x[k]
        x[i] = s / L[i, i]
