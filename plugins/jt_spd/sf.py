"""``spd=sf``: Stable PD by Featherstone's sparse L^T L factorisation (thesis 001 §2.2.3, "SF")."""

from __future__ import annotations

import dataclasses

from jt_spd.base import ToolkitSPD


class SparseBackend(ToolkitSPD):
    """Stable PD by sparse factorisation exploiting branch-induced sparsity (thesis 001 §2.2.3)."""

    method = "sf"

    @dataclasses.dataclass
    class Config:
        name: str = "sf"
        """Registry name."""
