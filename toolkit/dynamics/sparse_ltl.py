"""Sparse ``L^T L`` factorisation exploiting branch-induced sparsity (Featherstone RBDA §6.5).

For a kinematic tree, ``M[i, j] != 0`` only if DoF ``i`` is an ancestor or descendant of DoF
``j``. With DoFs numbered so that every parent precedes its children (``lam[i] < i``, the
``Model.dof_parent`` array), ``M = L^T L`` with ``L`` lower triangular has the same sparsity, and
factorising only touches ancestor pairs: O(n d^2) time for ``n`` DoFs and depth ``d`` (the SF
method of thesis §2.2.3; it degenerates to O(n^3) on a chain).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def ltl_factor(A: np.ndarray, lam: np.ndarray) -> None:
    """In-place ``A = L^T L`` on the ancestor entries of the lower triangle (RBDA Table 6.3).

    Args:
        A: symmetric positive-definite matrix ``(n, n)`` with tree sparsity; on return its lower
            triangle (ancestor entries) holds ``L``.
        lam: parent DoF of each DoF ``(n,)``, -1 for a root DoF; ``lam[i] < i``.
    """
    n = A.shape[0]
    for k in range(n - 1, -1, -1):
        A[k, k] = math.sqrt(A[k, k])
        i = lam[k]
        while i != -1:
            A[k, i] /= A[k, k]
            i = lam[i]
        i = lam[k]
        while i != -1:
            j = i
            aki = A[k, i]
            while j != -1:
                A[i, j] -= aki * A[k, j]
                j = lam[j]
            i = lam[i]


@njit(cache=True)
def ltl_solve(L: np.ndarray, lam: np.ndarray, b: np.ndarray, x: np.ndarray) -> None:
    """Solve ``L^T L x = b`` with the factor from ``ltl_factor`` (RBDA Table 6.4)."""
    n = L.shape[0]
    for i in range(n):
        x[i] = b[i]
    for i in range(n - 1, -1, -1):  # x = L^-T x
        x[i] /= L[i, i]
        j = lam[i]
        while j != -1:
            x[j] -= L[i, j] * x[i]
            j = lam[j]
    for i in range(n):  # x = L^-1 x
        j = lam[i]
        while j != -1:
            x[i] -= L[i, j] * x[j]
            j = lam[j]
        x[i] /= L[i, i]
