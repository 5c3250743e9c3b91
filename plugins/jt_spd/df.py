"""``spd=df``: Stable PD by dense Cholesky of ``M + Kd dt`` (thesis 001 §2.2.3, "DF")."""

from __future__ import annotations

import dataclasses

from jt_spd.base import ToolkitSPD


class DenseBackend(ToolkitSPD):
    """Stable PD by dense factorisation: M by CRBA, C by RNEA, Cholesky (thesis 001 §2.2.3)."""

    method = "df"

    @dataclasses.dataclass
    class Config:
        name: str = "df"
        """Registry name."""
