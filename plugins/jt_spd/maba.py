"""``spd=maba``: Stable PD by the modified articulated-body algorithm, O(n) (thesis 001 §2.3)."""

from __future__ import annotations

import dataclasses

from jt_spd.base import ToolkitSPD


class MabaBackend(ToolkitSPD):
    """Stable PD by MABA: ABA with the SPD constraint, linear time (thesis 001 §2.3)."""

    method = "maba"

    @dataclasses.dataclass
    class Config:
        name: str = "maba"
        """Registry name."""
