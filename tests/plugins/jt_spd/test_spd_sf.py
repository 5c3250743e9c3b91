"""``spd=sf``: the shared SPD backend suite."""

from __future__ import annotations

from toolkit.testing.spd import SPDBackendSuite

from jt_spd.sf import SparseBackend


class TestSparseBackend(SPDBackendSuite):
    backend_cls = SparseBackend
