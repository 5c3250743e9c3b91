"""``sim=bullet`` passes the simulator contract suite (``simulator_contract.py``)."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from simulator_contract import SimulatorContract  # noqa: E402


class TestBulletSimulator(SimulatorContract):
    def make(self, **sim):
        from jt_tasks.policy.env import load_simulator

        return load_simulator({"sim": {"name": "bullet", **sim}, "spd": {"name": "df"},
                               "character": {"name": "humanoid"}})
