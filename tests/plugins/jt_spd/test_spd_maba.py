"""``spd=maba``: the shared SPD backend suite."""

from __future__ import annotations

from spd_backend_suite import SPDBackendSuite

from jt_spd.maba import MabaBackend


class TestMabaBackend(SPDBackendSuite):
    backend_cls = MabaBackend
