"""PyBullet worlds for the shared SPD backend suite (``toolkit.testing.spd``) and jt's own tests.

``make_world`` opens a DIRECT client (y-up gravity, 600 Hz) with one of jt's characters (and a
ground plane); ``BulletSPDWorlds`` is the mixin that hands such worlds to ``SPDBackendSuite``::

    class TestMyBackend(BulletSPDWorlds, SPDBackendSuite):
        backend_cls = MyBackend

Imported by tests only (``toolkit.testing.spd`` imports pytest).
"""

from __future__ import annotations

import math
from typing import Any

from toolkit.testing.spd import DT, SPDWorld


def make_world(name: str, fixed: bool = False, plane: bool = False, **kw: Any) -> tuple:
    """``(client, Character, BulletBody)``: character ``name`` in a fresh DIRECT client.

    Args:
        name: a ``jt_bullet.characters`` name (``humanoid``, ``snake36`` ...).
        fixed: fix the base.
        plane: add the ground plane (y-up, height 0).
        **kw: passed to ``jt_bullet.characters.load`` (``self_collision`` ...).
    """
    import pybullet as pb
    import pybullet_data

    from jt_bullet.characters import load

    c = pb.connect(pb.DIRECT)
    pb.setGravity(0, -9.8, 0, physicsClientId=c)
    pb.setTimeStep(DT, physicsClientId=c)
    if plane:
        pb.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=c)
        z2y = pb.getQuaternionFromEuler([-math.pi * 0.5, 0, 0])
        pb.loadURDF("plane_implicit.urdf", [0, 0, 0], z2y, useMaximalCoordinates=True,
                    physicsClientId=c)
    ch = load(name, c, fixed_base=fixed, **kw)
    return c, ch, ch.body_io()


class BulletSPDWorlds:
    """Mixin: ``SPDBackendSuite.make_world`` from jt's PyBullet characters."""

    def make_world(self, name: str, plane: bool = False) -> Any:
        """Character ``name`` alone in a fresh PyBullet world, as a ``toolkit.testing.spd.SPDWorld``."""
        import pybullet as pb

        c, ch, io = make_world(name, plane=plane)
        return SPDWorld(model=io.model, io=io, q_init=ch.q_init, kp=ch.kp, kd=ch.kd,
                        torque_limit=ch.torque_limit,
                        close=lambda: pb.disconnect(physicsClientId=c), character=ch)
