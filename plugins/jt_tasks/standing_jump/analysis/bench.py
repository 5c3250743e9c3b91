"""Seconds per standing-jump evaluation (one simulation), and where the time goes: a benchmark.

Run ``jt study standing_jump bench [--n 10] [--sim-hz 600] [--spd maba] [--json FILE]``. Speed is
measured here, never in tests. Evaluations are the seed controller and seeded perturbations of it
(successes and failures both count: a search evaluates both).
"""

from __future__ import annotations

import json
import math
import platform
import time
from typing import Any, Optional, Sequence

from toolkit.errors import JtError, one_line_errors
from toolkit.study import parser, writable_file

PROG = "jt study standing_jump bench"


def time_evaluations(n: int = 10, sim_hz: float = 600.0, sigma: float = 0.03, seed: int = 0,
                     spd: str = "maba") -> dict[str, Any]:
    """Wall and CPU seconds per evaluation over ``n`` evaluations.

    Args:
        n: evaluations (the first is the seed controller, the rest perturbations of it).
        sim_hz: simulation rate.
        sigma: perturbation size, as a fraction of each parameter's range.
        seed: seed of the perturbations.
        spd: SPD backend (maba, df, sf, pcg).

    Returns:
        ``{"wall_s": [...], "cpu_s": [...], "sim_s": [...], "success": [...], "median_wall_s": ...,
        "median_cpu_s": ..., "realtime_factor": ...}``.
    """
    import numpy as np

    from jt_tasks.standing_jump import params as P
    from jt_tasks.standing_jump.simulate import SimSettings, simulate

    sp = P.space()
    rng = np.random.default_rng(seed)
    st = SimSettings(sim_hz=sim_hz, spd={"name": spd})
    simulate(sp.to_dict(sp.defaults()), st)  # warm-up: imports, URDF cache
    out: dict[str, list] = {"wall_s": [], "cpu_s": [], "sim_s": [], "success": []}
    lo, hi = np.array(sp.lows), np.array(sp.highs)
    for i in range(n):
        x = np.array(sp.defaults())
        if i:
            x = np.clip(x + sigma * (hi - lo) * rng.normal(size=x.size), lo, hi)
        w0, c0 = time.perf_counter(), time.process_time()
        r = simulate(sp.to_dict(x), st)
        out["wall_s"].append(time.perf_counter() - w0)
        out["cpu_s"].append(time.process_time() - c0)
        out["sim_s"].append(r.sim_time)
        out["success"].append(r.success)
    res: dict[str, Any] = dict(out)
    res["median_wall_s"] = float(np.median(out["wall_s"]))
    res["median_cpu_s"] = float(np.median(out["cpu_s"]))
    res["realtime_factor"] = float(np.sum(out["sim_s"]) / np.sum(out["cpu_s"]))
    res["sim_hz"] = sim_hz
    res["spd"] = spd
    res["machine"] = {"cpu": platform.processor() or platform.machine(), "python": platform.python_version()}
    return res


@one_line_errors
def main(argv: Optional[Sequence[str]] = None) -> None:
    from toolkit import plugins

    ap = parser(PROG, __doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=10, help="evaluations (default 10: the seed and 9 perturbations)")
    ap.add_argument("--sim-hz", type=float, default=600.0, help="simulation rate, Hz (default 600)")
    ap.add_argument("--spd", type=str, default="maba", help="SPD backend (default maba; jt plugins spd lists them)")
    ap.add_argument("--json", type=str, default="", help="also write the results as JSON here")
    a = ap.parse_args(argv)
    if a.n < 1:
        raise JtError(f"--n={a.n}: at least 1 evaluation")
    if not (math.isfinite(a.sim_hz) and a.sim_hz > 0):
        raise JtError(f"--sim-hz={a.sim_hz}: a finite rate > 0 (e.g. --sim-hz 600)")
    usable = [n for n in plugins.names("spd") if not getattr(plugins.load("spd", n), "steps_itself", False)]
    if a.spd not in usable:  # the standing jump adds its own torques: not a backend that steps itself
        raise JtError(f"--spd={a.spd}: not an SPD backend the standing jump can use; choose one of: "
                      f"{', '.join(sorted(usable))}")
    out = writable_file(a.json, "--json") if a.json else None
    res = time_evaluations(a.n, a.sim_hz, spd=a.spd)
    print(f"{a.n} evaluations at {a.sim_hz:g} Hz, spd={a.spd}: median wall {res['median_wall_s']:.3f} s, "
          f"median CPU {res['median_cpu_s']:.3f} s, {res['realtime_factor']:.1f}x real time, "
          f"{sum(res['success'])}/{a.n} successful")
    if out is not None:
        with open(out, "w") as f:
            json.dump(res, f, indent=2)


if __name__ == "__main__":
    main()
