"""``spd=maba``: the shared SPD backend suite."""

from __future__ import annotations

from jt_bullet.testing import BulletSPDWorlds
from toolkit.testing.spd import SPDBackendSuite

from jt_spd.maba import MabaBackend


class TestMabaBackend(BulletSPDWorlds, SPDBackendSuite):
    backend_cls = MabaBackend
