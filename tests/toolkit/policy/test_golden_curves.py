"""The policy-task layer changed no behaviour: short same-seed learning curves of ``highjump`` and
``runup`` equal the ones recorded on the commit before it (``golden/*.json``, every PPO statistic
per iteration and the deterministic rollout's trajectory).

Recorded with ``spd=maba``: before the layer, the tasks' ``task.spd: df`` fallback never fired
(conf/config.yaml always chose maba), so maba is what ran then; the tasks now choose df through
their YAML defaults (docs/configuration.md).

One intended change since: the high jump's strategy feature (the root orientation when the CoM
crosses the bar plane) now takes the CoM of the state just integrated (forward kinematics in the
simulator's substep loop) instead of PyBullet's cached link frames, which lag one 600 Hz substep
behind; the crossing is found one substep earlier, moving the feature by ~0.005 rad. Everything
else — every PPO statistic, the trajectory — is unchanged to the last digit.

Machines: the last digits of a training curve depend on the CPU (numpy's and torch's SIMD kernels),
and learning amplifies them (on an AMD EPYC the original recording's runup curve differs by up
to 5 % in ``clip_frac``, from the same code). So a machine has its own recording,
``<task>_smoke.<machine key>.json`` (``machine_key``: CPU model and SIMD features, numpy and
torch versions), made from the commit before a change with ``JT_RECORD_GOLDEN=1``, and is held to
it strictly (1e-9). A machine without one is held to the original recording loosely (10 %, 1e-3
absolute): the same behaviour, not the same bits.

A second, in session 5: the high jump's wall and mat are centred where the take-off velocity
crosses the bar plane (docs/highjump.md), which moves the scene and the along-the-bar coordinate
of the observation, so ``highjump_smoke.json`` was re-recorded on that change (its
``recorded_at`` says so); ``runup_smoke.json`` is still the recording from before the layer.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from toolkit.testing.golden import machine_key
from toolkit.rl.ppo import TIMING as ppo_timing

GOLDEN = Path(__file__).parent / "golden"
TIMING = set(ppo_timing)  # wall-clock keys: they differ between identical runs


def _tree(path: Path, group: str = "") -> dict:
    """Numeric datasets of an HDF5 file (below ``group``) by path, flattened."""
    import h5py

    out = {}
    with h5py.File(path, "r") as f:
        def walk(g, pre):
            for k in g:
                if isinstance(g[k], h5py.Dataset):
                    if g[k].dtype.kind in "fiub":
                        out[pre + k] = np.asarray(g[k][()], dtype=float).ravel()
                else:
                    walk(g[k], pre + k + "/")
        walk(f[group] if group else f, "")
    return out


@pytest.mark.parametrize("task", ["highjump", "runup"])
def test_same_seed_curve_equals_the_recording_before_the_layer(task, tmp_path):
    from tests.conftest import run_jt

    # a fresh process, as a user's `jt run`: in a test process that trained other policies before, the
    # high jump's 4th iteration moved by ~2e-8 (a process-state dependence not yet found: docs/ppo.md)
    done = run_jt("run", f"task={task}", "experiment=smoke", "agent.total_samples=256", "spd=maba", f"store={tmp_path}")
    assert done.returncode == 0, done.stderr
    art = next(p.parent for p in sorted((tmp_path / "runs").rglob("ppo.h5")))
    original = json.loads((GOLDEN / f"{task}_smoke.json").read_text())
    hist, ro = _tree(art / "ppo.h5", "history"), _tree(art / "rollout.h5")
    own = GOLDEN / f"{task}_smoke.{machine_key()}.json"
    if os.environ.get("JT_RECORD_GOLDEN"):  # run on the commit before a change, on a new machine
        own.write_text(json.dumps({
            "recorded_with": "JT_RECORD_GOLDEN=1 on the machine this key names; see the module docstring",
            "history": {k: hist[k].tolist() for k in original["history"]},
            "rollout": {k: ro[k].tolist() for k in original["rollout"]}}, indent=1) + "\n")
    strict = own.exists()
    golden = json.loads(own.read_text()) if strict else original
    rtol, atol = (1e-9, 1e-12) if strict else (0.1, 1e-3)
    for key, values in golden["history"].items():
        np.testing.assert_allclose(hist[key], values, rtol=rtol, atol=atol, err_msg=f"{key} (strict: {strict})")
    for key, values in golden["rollout"].items():
        if key.startswith("feature_") and not strict:  # the crossing is taken one substep earlier (see above)
            np.testing.assert_allclose(ro[key], values, atol=0.01, err_msg=key)
            continue
        np.testing.assert_allclose(ro[key], values, rtol=rtol, atol=atol, err_msg=f"{key} (strict: {strict})")
    assert len(golden["history"]["policy_loss"]) == 4  # four PPO iterations were compared
