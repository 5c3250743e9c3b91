"""``sim=bullet`` passes the simulator contract suite (``toolkit.testing.simulator``)."""

from __future__ import annotations

from toolkit.testing.simulator import SimulatorContract


class TestBulletSimulator(SimulatorContract):
    def make(self, **sim):
        from toolkit.policy.env import load_simulator

        return load_simulator({"sim": {"name": "bullet", **sim}, "spd": {"name": "df"},
                               "character": {"name": "humanoid"}})


class TestBulletSimulatorPythonLoop(SimulatorContract):
    """The same contract on the reference Python substep loop (``sim.loop=python``)."""

    def make(self, **sim):
        from toolkit.policy.env import load_simulator

        return load_simulator({"sim": {"name": "bullet", "loop": "python", **sim}, "spd": {"name": "df"},
                               "character": {"name": "humanoid"}})
