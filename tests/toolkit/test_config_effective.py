"""What ``jt run ... --cfg`` would print, for every task under every experiment and every style
preset, is what it was when recorded (``golden/effective_configs.json``): moving a default between
the dataclasses and the YAML files (issue 27) changes no effective value. A deliberate change of
a default re-records it: ``JT_RECORD_GOLDEN=1 python -m pytest tests/toolkit/test_config_effective.py``,
with the change named in the commit."""

from __future__ import annotations

import json
import os
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RECORDING = Path(__file__).parent / "golden" / "effective_configs.json"


def effective_configs() -> dict:
    """``{"<task>/<experiment or preset>": composed config (unresolved) or "error: <line>"}``."""
    from omegaconf import OmegaConf

    from toolkit.config import compose

    out = {}
    tasks = sorted(p.stem for p in (ROOT / "conf" / "task").glob("*.yaml"))
    experiments = sorted(p.stem for p in (ROOT / "conf" / "experiment").glob("*.yaml"))
    for t in tasks:
        for e in experiments:
            try:
                out[f"{t}/{e}"] = OmegaConf.to_container(compose([f"task={t}", f"experiment={e}"]), resolve=False)
            except Exception as ex:  # noqa: BLE001 - a refused pair is recorded as refused
                out[f"{t}/{e}"] = f"error: {str(ex).splitlines()[0]}"
    for p in sorted((ROOT / "conf" / "preset").glob("style_*.yaml")):
        out[f"spacetime/{p.stem}"] = OmegaConf.to_container(compose(["task=spacetime", f"preset={p.stem}"]),
                                                            resolve=False)
    return json.loads(json.dumps(out, sort_keys=True, default=str))


def test_every_task_and_preset_composes_to_the_recorded_values():
    got = effective_configs()
    if os.environ.get("JT_RECORD_GOLDEN"):
        RECORDING.write_text(json.dumps(got, indent=0, sort_keys=True))
    want = json.loads(RECORDING.read_text())
    assert sorted(got) == sorted(want)
    changed = [k for k in want if got[k] != want[k]]
    assert not changed, f"effective config changed for {changed}"
