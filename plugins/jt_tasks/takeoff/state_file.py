"""``takeoff_state.h5``: the simulated state at the end of a run-up, for the jump tasks to start from.

Layout (``toolkit.store.h5``; read it back with ``read_takeoff_state`` or plain h5py):

=================  ==========  ================================================================
name               shape       meaning
=================  ==========  ================================================================
``q``              ``(n_q,)``  generalised positions, ``toolkit.dynamics`` layout (root x, y, z,
                               quaternion x, y, z, w, then the joints' quaternions / angles),
                               turned about +y so that the heading is +x and the root stands
                               above the origin: the convention of ``jt_tasks.takeoff.state``'s
                               ``TakeoffState.q`` (the jump env re-places the take-off foot)
``qd``             ``(n_dof,)`` generalised velocities in the same frame (root linear and angular
                               velocity, then local joint angular velocities / angle rates)
``q_world``        ``(n_q,)``  the same state where the simulation left it
``qd_world``       ``(n_dof,)``
``features/*``     scalars     achieved take-off features in the facing frame: ``omega_x``,
                               ``omega_y``, ``omega_z``, ``v_z`` (``jt_tasks.runup.reward.measure``)
``target_features/*`` scalars  the targets r_G compared them with (eq 13 / 14)
``foot``           string      take-off foot (``right`` / ``left``)
``kind``           string      ``highjump`` / ``obstacle``
``time``           scalar      clip phase time (s, within one cycle) of the take-off instant
``r_goal``         scalar      r_G reached (``000`` eq 13 / 14)
=================  ==========  ================================================================
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

import numpy as np

NAME = "takeoff_state.h5"


def write_takeoff_state(path: str | Path, q_world: np.ndarray, qd_world: np.ndarray, features: Mapping[str, float],
                        targets: Mapping[str, float], foot: str, kind: str, time: float, r_goal: float) -> Path:
    """Write the file described above; ``q``/``qd`` are derived from the world state."""
    from jt_tasks.takeoff.state import normalise_heading
    from toolkit.store import h5

    q, qd = normalise_heading(q_world, qd_world)
    return h5.write(Path(path), {
        "q": q, "qd": qd, "q_world": np.asarray(q_world, dtype=float), "qd_world": np.asarray(qd_world, dtype=float),
        "features": {k: float(v) for k, v in features.items()},
        "target_features": {k: float(v) for k, v in targets.items()},
        "foot": str(foot), "kind": str(kind), "time": float(time), "r_goal": float(r_goal),
    }, {"format": "jt.runup.takeoff_state/1"})


def read_takeoff_state(path: str | Path) -> Any:
    """The file as a ``jt_tasks.takeoff.state.TakeoffState`` (features = the achieved ones).

    Raises:
        JtError: one line when the file is not HDF5, or lacks or mangles one of ``q``, ``qd``,
            ``time``, ``foot``, ``features`` (e.g. a truncated copy or another kind of file).
    """
    from jt_tasks.takeoff.state import TakeoffState
    from toolkit.errors import JtError
    from toolkit.store import h5

    what = f"task.takeoff_from={path}"
    hint = "give a task=runup run id, its folder, or its takeoff_state.h5 (make one with: jt run task=runup)"
    try:
        d = h5.read(Path(path))
    except (OSError, ValueError) as e:
        raise JtError(f"{what}: not a readable HDF5 file ({str(e).splitlines()[0]}); {hint}") from e
    missing = [k for k in ("q", "qd", "time", "foot", "features") if k not in d]
    if missing:
        raise JtError(f"{what}: not a take-off state (no {', '.join(missing)}); {hint}")
    try:
        q, qd = np.asarray(d["q"], dtype=float).ravel(), np.asarray(d["qd"], dtype=float).ravel()
        features = {k: float(v) for k, v in dict(d["features"]).items()}
        ts = TakeoffState(q=q, qd=qd, time=float(d["time"]), foot=str(d["foot"]), features=features)
    except (TypeError, ValueError) as e:
        raise JtError(f"{what}: a malformed take-off state ({type(e).__name__}: {e}); {hint}") from e
    if len(q) < 7 or len(qd) < 6 or not (np.all(np.isfinite(q)) and np.all(np.isfinite(qd))):
        raise JtError(f"{what}: a malformed take-off state (q has {len(q)} values, qd {len(qd)}, "
                      f"or one is not finite); {hint}")
    return ts
