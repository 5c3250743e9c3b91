"""``spd=pcg``: the shared SPD backend suite."""

from __future__ import annotations

from jt_bullet.testing import BulletSPDWorlds
from toolkit.testing.spd import SPDBackendSuite

from jt_spd.pcg import PCGBackend


class TestPCGBackend(BulletSPDWorlds, SPDBackendSuite):
    backend_cls = PCGBackend

    def test_tolerance_from_config_sets_the_work_done(self):
        import numpy as np
        import pybullet as pb
        from jt_bullet.testing import make_world
        from toolkit.testing.spd import DT

        c, ch, _ = make_world("snake36")
        try:
            model = ch.model()
            rng = np.random.default_rng(0)
            q, qd = model.random_state(rng)
            qt, _ = model.random_state(rng)
            its = {}
            for tol in (1e-4, 1e-12):
                b = PCGBackend({"name": "pcg", "tol": tol, "max_iter_factor": 20})
                b.bind(model)
                b.torques(q, qd, qt, ch.kp, ch.kd, DT)
                its[tol] = b.data.iterations
            assert 0 < its[1e-4] < its[1e-12] <= 20 * model.n_v
        finally:
            pb.disconnect(c)
