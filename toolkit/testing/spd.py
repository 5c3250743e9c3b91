"""Shared test suite every SPD backend's test module subclasses (Hydra-style test base class).

A subclass sets ``backend_cls`` (and ``reference_exact``: whether its torques must equal exact
SPD from ``toolkit.dynamics``) and inherits every test::

    from toolkit.testing.spd import SPDBackendSuite

    class TestMyBackend(SPDBackendSuite):
        backend_cls = MyBackend

The worlds are PyBullet bodies of jt's built-in characters (``jt_bullet.characters``, imported
when a test builds one); ``make()`` builds the backend (``backend_cls(None)`` by default).
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

import numpy as np
import pytest

DT = 1.0 / 600.0


def make_world(name: str, fixed: bool = False, plane: bool = False, **kw: Any) -> tuple:
    """(client, Character, BulletBody) in a fresh DIRECT client, y-up gravity."""
    import math

    import pybullet as pb
    import pybullet_data

    from jt_bullet.characters import load
    from toolkit.dynamics.bullet_io import BulletBody

    c = pb.connect(pb.DIRECT)
    pb.setGravity(0, -9.8, 0, physicsClientId=c)
    pb.setTimeStep(DT, physicsClientId=c)
    if plane:
        pb.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=c)
        z2y = pb.getQuaternionFromEuler([-math.pi * 0.5, 0, 0])
        pb.loadURDF("plane_implicit.urdf", [0, 0, 0], z2y, useMaximalCoordinates=True,
                    physicsClientId=c)
    ch = load(name, c, fixed_base=fixed, **kw)
    return c, ch, BulletBody(c, ch.body_id, ch.model())


class SPDBackendSuite:
    """Tests every ``jt.spd`` backend must pass."""

    backend_cls: ClassVar[type] = None  # type: ignore[assignment]
    #: torques equal toolkit.dynamics' exact SPD (False for PyBullet's own controller)
    reference_exact: ClassVar[bool] = True

    @pytest.fixture(scope="class")
    def humanoid(self) -> Any:
        import pybullet as pb

        world = make_world("humanoid", plane=True)
        yield world
        pb.disconnect(world[0])

    def make(self) -> Any:
        return self.backend_cls(None)

    # ---- plugin contract ---------------------------------------------------------------------
    def test_is_a_plugin_with_config_and_summary(self):
        from toolkit.interfaces import SPDBackend

        assert issubclass(self.backend_cls, SPDBackend)
        assert dataclasses.is_dataclass(self.backend_cls.Config)
        names = {f.name for f in dataclasses.fields(self.backend_cls.Config)}
        assert "name" in names
        assert self.backend_cls.summary()  # one-line docstring summary

    def test_module_imports_nothing_heavy(self):
        import subprocess
        import sys

        mod = self.backend_cls.__module__
        code = (f"import sys, {mod}; heavy = [m for m in ('numba', 'pybullet', 'torch') "
                "if m in sys.modules]; assert not heavy, heavy")
        subprocess.run([sys.executable, "-c", code], check=True)

    # ---- behaviour ---------------------------------------------------------------------------
    def test_holds_the_humanoid_standing(self, humanoid):
        """Tracking the loaded pose for 0.5 s on the ground: stays upright, no NaN."""
        c, ch, io = humanoid
        backend = self.make()
        backend.bind(io if self.backend_cls.steps_itself else ch.model())
        io.reset(ch.q_init, np.zeros(ch.n_dof))
        for _ in range(300):
            backend.control(io, ch.q_init, ch.kp, ch.kd, DT, ch.torque_limit)
            io.step()
        q, qd = io.read()
        assert np.all(np.isfinite(q)) and np.all(np.isfinite(qd))
        assert abs(q[1] - ch.q_init[1]) < 0.05  # root height (y-up) within 5 cm
        assert np.abs(qd).max() < 1.0

    def test_torques_match_exact_spd(self):
        if not self.reference_exact:
            pytest.skip("not an exact-SPD backend")
        import pybullet as pb

        from toolkit.dynamics.spd import spd_torques

        for name in ("humanoid", "snake36", "atlas"):
            c, ch, io = make_world(name)
            try:
                model = ch.model()
                backend = self.make()
                backend.bind(model)
                from toolkit.dynamics.model import Data

                data = Data(model)
                rng = np.random.default_rng(0)
                for _ in range(2):
                    q, qd = model.random_state(rng)
                    qt, _ = model.random_state(rng)
                    tau = np.array(backend.torques(q, qd, qt, ch.kp, ch.kd, DT))
                    ref = spd_torques(model, data, q, qd, qt, ch.kp, ch.kd, DT, method="df")
                    assert np.abs(tau - ref).max() <= 1e-8 * np.abs(ref).max(), name
            finally:
                pb.disconnect(c)

    def test_unbound_backend_says_so(self):
        backend = self.make()
        q = np.zeros(7)
        with pytest.raises((RuntimeError, NotImplementedError)):
            backend.torques(q, np.zeros(6), q, np.zeros(6), np.zeros(6), DT)


#: the same suite under the name the other kinds use
SPDBackendContract = SPDBackendSuite
