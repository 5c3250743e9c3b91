"""``spd=maba``: the shared SPD backend suite."""

from __future__ import annotations

from toolkit.testing.spd import SPDBackendSuite

from jt_spd.maba import MabaBackend


class TestMabaBackend(SPDBackendSuite):
    backend_cls = MabaBackend
