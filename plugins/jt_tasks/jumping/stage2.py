"""Stage 2, novel policy seeking (``000`` §5.2): NOT IMPLEMENTED YET.

The plan: ``task.stage=2 task.init=<Stage-1 evaluation folder>`` reads the take-off features from
its ``rollout.h5``, warm-starts PPO from its ``ppo.h5`` (weights only, counters reset), and trains
with ``reward=highjump_stage2`` whose ``novelty`` term (``000`` eq 12) compares each episode's
root orientation at the bar (``JumpEnv.episode_record()["feature"]``, quaternion in the suite frame)
with ``task.policy_features``. The environment already records that feature and passes
``policy_features``; what is missing is the warm start and the run-id lookup.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any


def prepare(spec: Any, params: Any, workdir: Path) -> Any:
    """Stage-2 set-up of an evaluation (not implemented: raises a one-line ``JtError``)."""
    from toolkit.errors import JtError

    raise JtError("task.stage=2 (novel policy seeking, 000 §5.2) is not implemented yet; "
                  "run Stage 1 (task.stage=1)")
