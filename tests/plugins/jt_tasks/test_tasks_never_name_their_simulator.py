"""Tasks reach PyBullet only through the simulator plugin (MimicKit's engine interface): no module
under plugins/jt_tasks imports pybullet, and none imports another plugin package."""

from __future__ import annotations

import re
from pathlib import Path

TASKS = Path(__file__).resolve().parents[3] / "plugins" / "jt_tasks"
OTHER_PLUGINS = ("jt_bullet", "jt_spd", "jt_actions", "jt_rewards", "jt_curricula", "jt_searchers", "jt_executors")


def test_no_task_module_imports_pybullet_or_another_plugin():
    bad = []
    for path in sorted(TASKS.rglob("*.py")):
        for n, line in enumerate(path.read_text().splitlines(), 1):
            code = line.split("#", 1)[0]
            if re.search(r"^\s*(import|from)\s+pybullet(_data)?\b", code):
                bad.append(f"{path.relative_to(TASKS)}:{n}: {line.strip()}")
            if re.search(rf"^\s*(import|from)\s+({'|'.join(OTHER_PLUGINS)})\b", code):
                bad.append(f"{path.relative_to(TASKS)}:{n}: {line.strip()}")
    assert not bad, "\n".join(bad)
