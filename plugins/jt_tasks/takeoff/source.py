"""``task.takeoff_from``: start the jump from a run-up controller's simulated take-off state.

By default a jump starts from a frame of the run clip with the explored features imposed
(``jt_tasks.takeoff.state.takeoff_state``). ``000`` §6.1.1 instead reaches each take-off state
with a run-up controller; ``task=runup`` trains one and writes ``takeoff_state.h5``
(``jt_tasks.takeoff.state_file``). Setting ``task.takeoff_from`` to

* a ``task=runup`` run id (a nested evaluation, or an outer run: its evaluation with the highest
  ``goal_reward``, or the run itself for ``search=single``),
* a folder holding ``takeoff_state.h5`` (or one folder down), or the file itself
  (``toolkit.store.resolve``),

makes the jump start from that state: the achieved features become the task's fixed take-off
features (only ``alpha``, which rotates the suite, is left to search), and ``v_y`` (the jumping
intention, ``jt_tasks.takeoff.state.takeoff_state``) still replaces the vertical root speed unless
it is null.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

import numpy as np

from jt_tasks.takeoff.state_file import NAME


def _err(msg: str) -> Exception:
    from toolkit.errors import JtError

    return JtError(msg)


def _goal_reward(run: Any) -> float:
    """Which run-up evaluation is best: the highest ``goal_reward`` (r_G, ``000`` eq 13 / 14)."""
    return run.data.metrics.get("goal_reward", 0.0)


def resolve(ref: str, store_path: Optional[str]) -> Path:
    """The ``takeoff_state.h5`` that ``task.takeoff_from=ref`` names; a one-line error otherwise.

    Args:
        ref: a ``task=runup`` run id (see the module docstring), a folder holding the file, or the file.
        store_path: the store to look run ids up in (``toolkit.store.tracking.store_root`` rules).
    """
    from toolkit.store.resolve import resolve as find

    return find(ref, artifact=NAME, store=store_path, best_by=_goal_reward, what="task.takeoff_from",
                label="take-off state", hint="is it a task=runup run? make one with: jt run task=runup").path


def load(path: str | Path, foot: str, v_y: Optional[float]) -> Any:
    """The ``TakeoffState`` of ``path`` with ``v_y`` imposed; its foot must be the task's."""
    from jt_tasks.takeoff.state import impose
    from jt_tasks.takeoff.state_file import read_takeoff_state

    ts = read_takeoff_state(path)
    if ts.foot != foot:
        raise _err(f"task.takeoff_from: the run-up took off from the {ts.foot} foot, the task uses "
                   f"task.foot={foot}; choose one of: {ts.foot}")
    if v_y is not None:
        v, w = impose(ts.q[3:7], ts.qd[:3], ts.qd[3:6], {}, None, v_y)
        ts.qd = np.concatenate([v, w, ts.qd[6:]])
    return ts


def features(path: str | Path, names: tuple[str, ...]) -> dict[str, float]:
    """The achieved take-off features of ``path`` among ``names`` (``alpha`` is never one)."""
    from jt_tasks.takeoff.state_file import read_takeoff_state

    got = read_takeoff_state(path).features
    return {k: float(got[k]) for k in names if k in got}
