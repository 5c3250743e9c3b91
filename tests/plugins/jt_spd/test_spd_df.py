"""``spd=df``: the shared SPD backend suite."""

from __future__ import annotations

from toolkit.testing.spd import SPDBackendSuite

from jt_spd.df import DenseBackend


class TestDenseBackend(SPDBackendSuite):
    backend_cls = DenseBackend
