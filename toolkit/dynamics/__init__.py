"""Articulated-body dynamics (Pinocchio-style ``Model``/``Data``) and Stable PD backends.

Algorithms, one module each: ``crba`` (mass matrix), ``rnea`` (inverse dynamics, bias forces),
``aba`` (forward dynamics), ``maba`` (SPD in O(n), thesis ``001`` §2.3), ``sparse_ltl`` (the SF
factorisation), ``dense`` (DF Cholesky), ``pcg`` (Jacobi-PCG), ``spd`` (public SPD API).
A simulator plugin builds the ``Model`` of its bodies and times these (``jt bench spd``). Kernels are numba ``@njit(cache=True)`` functions compiled on first call;
importing this package imports nothing heavy (names below load their module on first access).
The algorithm functions share their module's name: ``from toolkit.dynamics.crba import crba``.
"""

from __future__ import annotations

import importlib
from typing import Any

_LAZY = {
    "Model": "toolkit.dynamics.model",
    "Data": "toolkit.dynamics.model",
    "bias": "toolkit.dynamics.rnea",
    "spd_torques": "toolkit.dynamics.spd",
    "spd_solve": "toolkit.dynamics.spd",
    "METHODS": "toolkit.dynamics.spd",
}

__all__ = sorted(_LAZY)


def __getattr__(name: str) -> Any:
    mod = _LAZY.get(name)
    if mod is None:
        raise AttributeError(f"module 'toolkit.dynamics' has no attribute {name!r}")
    return getattr(importlib.import_module(mod), name)
