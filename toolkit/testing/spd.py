"""Shared test suite every SPD backend's test module subclasses (Hydra-style test base class).

A subclass sets ``backend_cls`` (and ``reference_exact``: whether its torques must equal exact
SPD from ``toolkit.dynamics``) and inherits every test::

    from toolkit.testing.spd import SPDBackendSuite

    class TestMyBackend(SPDBackendSuite):
        backend_cls = MyBackend

The worlds come from the subclass: ``make_world(name, plane)`` returns an ``SPDWorld`` (the body's
``Model``, its I/O, gains and standing pose), so the suite runs on any simulator; this module
imports none. jt's own test modules take them from PyBullet (``jt_bullet.testing.BulletSPDWorlds``,
a mixin)::

    class TestMyBackend(BulletSPDWorlds, SPDBackendSuite):
        backend_cls = MyBackend

``make()`` builds the backend (``backend_cls(None)`` by default).
"""

from __future__ import annotations

import dataclasses
from typing import Any, Callable, ClassVar

import numpy as np
import pytest

DT = 1.0 / 600.0


@dataclasses.dataclass
class SPDWorld:
    """One character in a world of its own: what the suite drives a backend on.

    Attributes:
        model: the body's ``toolkit.dynamics.Model``.
        io: the simulator's body I/O: ``read() -> (q, qd)``, ``reset(q, qd)``,
            ``write_torques(tau)``, ``step()``; a ``steps_itself`` backend binds to it.
        q_init: the character's standing pose ``(n_q,)``.
        kp: stiffness per DoF ``(n_v,)``.
        kd: damping per DoF ``(n_v,)``.
        torque_limit: torque limit per DoF ``(n_v,)``.
        close: releases the world.
        character: the simulator's own handle of the body, for a subclass's own tests (or None).
    """

    model: Any
    io: Any
    q_init: np.ndarray
    kp: np.ndarray
    kd: np.ndarray
    torque_limit: np.ndarray
    close: Callable[[], None]
    character: Any = None


class SPDBackendSuite:
    """Tests every ``jt.spd`` backend must pass."""

    backend_cls: ClassVar[type] = None  # type: ignore[assignment]
    #: torques equal toolkit.dynamics' exact SPD (False for PyBullet's own controller)
    reference_exact: ClassVar[bool] = True
    #: characters whose torques ``test_torques_match_exact_spd`` compares (names ``make_world`` knows)
    exact_bodies: ClassVar[tuple[str, ...]] = ("humanoid", "snake36", "atlas")

    def make_world(self, name: str, plane: bool = False) -> SPDWorld:
        """The hook: character ``name`` (``"humanoid"``: floating base, y-up; and the
        ``exact_bodies``) alone in a fresh world with gravity ``(0, -9.8, 0)`` and time step ``DT``,
        on a ground plane at height 0 when ``plane``."""
        raise NotImplementedError(
            f"{type(self).__name__}: SPDBackendSuite needs worlds; define make_world(name, plane) "
            "returning an SPDWorld (jt's PyBullet ones: jt_bullet.testing.BulletSPDWorlds)")

    @pytest.fixture(scope="class")
    def humanoid(self) -> Any:
        world = self.make_world("humanoid", plane=True)
        yield world
        world.close()

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
        w = humanoid
        io = w.io
        backend = self.make()
        backend.bind(io if self.backend_cls.steps_itself else w.model)
        io.reset(w.q_init, np.zeros(w.model.n_v))
        for _ in range(300):
            backend.control(io, w.q_init, w.kp, w.kd, DT, w.torque_limit)
            io.step()
        q, qd = io.read()
        assert np.all(np.isfinite(q)) and np.all(np.isfinite(qd))
        assert abs(q[1] - w.q_init[1]) < 0.05  # root height (y-up) within 5 cm
        assert np.abs(qd).max() < 1.0

    def test_torques_match_exact_spd(self):
        if not self.reference_exact:
            pytest.skip("not an exact-SPD backend")
        from toolkit.dynamics.model import Data
        from toolkit.dynamics.spd import spd_torques

        for name in self.exact_bodies:
            w = self.make_world(name)
            try:
                model = w.model
                backend = self.make()
                backend.bind(model)
                data = Data(model)
                rng = np.random.default_rng(0)
                for _ in range(2):
                    q, qd = model.random_state(rng)
                    qt, _ = model.random_state(rng)
                    tau = np.array(backend.torques(q, qd, qt, w.kp, w.kd, DT))
                    ref = spd_torques(model, data, q, qd, qt, w.kp, w.kd, DT, method="df")
                    assert np.abs(tau - ref).max() <= 1e-8 * np.abs(ref).max(), name
            finally:
                w.close()

    def test_torques_come_back_unless_it_steps_itself(self, humanoid):
        """``torques`` returns finite ``(n_v,)`` torques; a ``steps_itself`` backend (PyBullet's own
        controllers) raises instead, naming itself."""
        w = humanoid
        backend = self.make()
        q, qd = w.q_init, np.zeros(w.model.n_v)
        if self.backend_cls.steps_itself:
            backend.bind(w.io)
            with pytest.raises(NotImplementedError, match=f"spd={backend.params.name} computes its torques"):
                backend.torques(q, qd, q, w.kp, w.kd, DT)
            return
        backend.bind(w.model)
        tau = np.array(backend.torques(q, qd, q, w.kp, w.kd, DT))
        assert tau.shape == (w.model.n_v,) and np.all(np.isfinite(tau))

    def test_unbound_backend_says_so(self):
        backend = self.make()
        q = np.zeros(7)
        with pytest.raises((RuntimeError, NotImplementedError)):
            backend.torques(q, np.zeros(6), q, np.zeros(6), np.zeros(6), DT)


#: the same suite under the name the other kinds use
SPDBackendContract = SPDBackendSuite
