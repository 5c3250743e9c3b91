"""SPD benchmarks (thesis ``001`` Tables 2.2 / 2.3): solve time, step time, agreement.

* ``time_spd`` times, per model and backend, the SPD solve alone on random states and one full
  simulation substep (read state from PyBullet + SPD + clip + apply torques + ``stepSimulation``;
  for ``bullet``, arming ``STABLE_PD_CONTROL`` + ``stepSimulation``). Backends are interleaved
  (solves in blocks of ``SOLVE_BLOCK`` states, substeps one by one with one world per backend) so
  that machine load affects all alike.
* ``check_agreement`` returns the largest relative torque difference between the four solvers.
* ``summarize`` turns the rows into the ratios the targets in ``docs/maba.md`` are stated in.

Characters come from ``loader(name, client)``; by default ``BulletSimulator.load_character``; pass
``loader`` to use another source. ``jt bench spd`` reaches this module through the registered
simulator (``BulletSimulator.spd_bench``): the toolkit imports no plugin.
"""

from __future__ import annotations

import math
import time
from typing import Any, Callable, Sequence

import numpy as np

from jt_bullet.body import PYBULLET_MAX_Q, BulletBody
from jt_bullet.model import model_from_bullet
from toolkit.dynamics.model import Data, Model
from toolkit.dynamics.spd import METHODS, spd_solve

BACKENDS = METHODS + ("bullet",)  #: ``jt bench spd``'s default backends (servo is opt-in: no solve to time)
MODELS = ("humanoid", "snake36", "snake72", "snake195")  #: ``jt bench spd``'s default characters (thesis Table 2.1)
SOLVE_BLOCK = 10  #: consecutive solves per backend before switching (keeps caches warm)


def default_loader() -> Callable[[str, int], Any]:
    """``characters.load_configured``: jt's characters with their config's gains."""
    from jt_bullet.characters import load_configured

    return load_configured


def _world(dt: float) -> int:
    """A DIRECT client, y-up gravity, a ground plane (as pybullet's DeepMimic env)."""
    import pybullet as pb
    import pybullet_data

    c = pb.connect(pb.DIRECT)
    kw = {"physicsClientId": c}
    pb.setAdditionalSearchPath(pybullet_data.getDataPath(), **kw)
    pb.setGravity(0, -9.8, 0, **kw)
    pb.setTimeStep(dt, **kw)
    z2y = pb.getQuaternionFromEuler([-math.pi * 0.5, 0, 0])
    pb.loadURDF("plane_implicit.urdf", [0, 0, 0], z2y, useMaximalCoordinates=True, **kw)
    return c


def random_targets(model: Model, q_ref: np.ndarray, rng: np.random.Generator,
                   spread: float = 0.3) -> np.ndarray:
    """Targets near ``q_ref``: joints rotated/moved by about ``spread`` rad (root kept)."""
    from toolkit.dynamics.model import JT_REVOLUTE, JT_PRISMATIC, JT_SPHERICAL
    from toolkit.dynamics.spatial import quat_exp, quat_mul

    qt = q_ref.copy()
    for i, t in enumerate(model.jtype):
        k = model.q_idx[i]
        if t == JT_SPHERICAL:
            e = quat_exp(*(spread * rng.normal(size=3)))
            qt[k:k + 4] = quat_mul(*qt[k:k + 4], *e)
        elif t in (JT_REVOLUTE, JT_PRISMATIC):
            qt[k] += spread * rng.normal()
    return qt


def _solve_states(model: Model, n: int, rng: np.random.Generator) -> list[tuple]:
    out = []
    for _ in range(n):
        q, qd = model.random_state(rng)
        qt, _ = model.random_state(rng)
        out.append((q, qd, qt))
    return out


def time_spd(model_names: Sequence[str], backends: Sequence[str] = BACKENDS,
             n_samples: int = 200, seed: int = 0, dt: float = 1.0 / 600.0,
             loader: Callable[[str, int], Any] | None = None) -> list[dict]:
    """Median SPD solve and simulation-step times per model and backend.

    Args:
        model_names: characters, e.g. ``["humanoid", "snake36", "snake195"]``.
        backends: any of ``maba``, ``df``, ``sf``, ``pcg``, ``bullet``, and ``servo`` (PyBullet's
            constraint motors, not an SPD: no solve time; not in the default ``BACKENDS``).
        n_samples: timed solves (random states) and timed substeps per backend.
        seed: seeds the random states and targets.
        dt: simulation time step (600 Hz as the jumping papers).
        loader: ``loader(name, client) -> Character``; default ``default_loader()``.

    Returns:
        One row per (model, backend): ``model``, ``dof``, ``depth``, ``backend``,
        ``solve_us_median`` (NaN for ``bullet`` and ``servo``, whose solve happens inside PyBullet's step) and
        ``step_us_median`` (NaN where PyBullet cannot drive the body: more than 128 position
        coordinates, see ``jt_bullet.body``).
    """
    import pybullet as pb

    load = loader or default_loader()
    rows = []
    for name in model_names:
        rng = np.random.default_rng(seed)
        c = _world(dt)
        ch = load(name, c)
        model = model_from_bullet(c, ch.body_id, name=name, floating=not ch.fixed_base)
        data = Data(model)
        kp, kd = np.asarray(ch.kp, float), np.asarray(ch.kd, float)
        ours = [b for b in backends if b in METHODS]
        # ---- solve: interleaved over random states
        solve = {b: [] for b in ours}
        states = _solve_states(model, n_samples, rng)
        for b in ours:  # warm up (JIT)
            spd_solve(model, data, *states[0][:2], states[0][2], kp, kd, dt, b)
        for k0 in range(0, n_samples, SOLVE_BLOCK):
            for b in ours:
                for q, qd, qt in states[k0:k0 + SOLVE_BLOCK]:
                    t0 = time.perf_counter_ns()
                    spd_solve(model, data, q, qd, qt, kp, kd, dt, b)
                    solve[b].append(time.perf_counter_ns() - t0)
        q_init = np.asarray(ch.q_init, float)
        pb.disconnect(c)
        # ---- step: one world per backend, substeps interleaved
        step = {b: [] for b in backends}
        if model.n_q <= PYBULLET_MAX_Q:
            step = _time_steps(name, backends, model, kp, kd, np.asarray(ch.torque_limit, float),
                               q_init, n_samples, seed, dt, load)
        for b in backends:
            rows.append({
                "model": name, "dof": model.n_v, "depth": model.depth, "backend": b,
                "solve_us_median": float(np.median(solve[b]) / 1e3) if solve.get(b) else math.nan,
                "step_us_median": float(np.median(step[b]) / 1e3) if step.get(b) else math.nan,
            })
    return rows


def _time_steps(name: str, backends: Sequence[str], model: Model, kp: np.ndarray,
                kd: np.ndarray, limit: np.ndarray, q_init: np.ndarray, n: int, seed: int,
                dt: float, load: Callable[[str, int], Any]) -> dict[str, list[int]]:
    import pybullet as pb

    worlds = []
    for b in backends:
        c = _world(dt)
        ch = load(name, c)
        io = BulletBody(c, ch.body_id, model)
        worlds.append((b, c, io, Data(model), np.empty(model.n_v)))
    rng = np.random.default_rng(seed + 1)
    q_target = random_targets(model, q_init, rng, spread=0.2)
    warm = 20
    out: dict[str, list[int]] = {b: [] for b in backends}
    for k in range(warm + n):
        for b, c, io, data, tau in worlds:
            t0 = time.perf_counter_ns()
            if b == "bullet":
                io.stable_pd(q_target, kp, kd, limit)
            elif b == "servo":  # PyBullet's constraint motors (spd=servo): no SPD at all
                io.servo(q_target, limit)
            else:
                q, qd = io.read()
                spd_solve(model, data, q, qd, q_target, kp, kd, dt, b)
                np.clip(data.tau, -limit, limit, out=tau)
                io.write_torques(tau)
            pb.stepSimulation(physicsClientId=c)
            if k >= warm:
                out[b].append(time.perf_counter_ns() - t0)
    for _, c, _, _, _ in worlds:
        pb.disconnect(c)
    return out


def check_agreement(models: Sequence[str], n_states: int = 20, seed: int = 0,
                    loader: Callable[[str, int], Any] | None = None) -> float:
    """Largest ``max|tau_m - tau_df| / max|tau_df|`` over models, random states and methods."""
    import pybullet as pb

    load = loader or default_loader()
    worst = 0.0
    for name in models:
        rng = np.random.default_rng(seed)
        c = pb.connect(pb.DIRECT)
        ch = load(name, c)
        model = model_from_bullet(c, ch.body_id, name=name, floating=not ch.fixed_base)
        pb.disconnect(c)
        data = Data(model)
        kp, kd = np.asarray(ch.kp, float), np.asarray(ch.kd, float)
        for q, qd, qt in _solve_states(model, n_states, rng):
            spd_solve(model, data, q, qd, qt, kp, kd, 1.0 / 600.0, "df")
            ref = data.tau.copy()
            scale = max(float(np.abs(ref).max()), 1e-12)
            for m in METHODS:
                spd_solve(model, data, q, qd, qt, kp, kd, 1.0 / 600.0, m)
                worst = max(worst, float(np.abs(data.tau - ref).max()) / scale)
    return worst


def summarize(rows: list[dict]) -> dict[str, float]:
    """The ratios the MABA targets are stated in (NaN where a row is missing)."""
    def get(model: str, backend: str, key: str) -> float:
        for r in rows:
            if r["model"] == model and r["backend"] == backend and math.isfinite(r[key]):
                return float(r[key])
        return float("nan")

    return {
        "df_over_maba_solve_195": get("snake195", "df", "solve_us_median")
        / get("snake195", "maba", "solve_us_median"),
        "df_over_maba_solve_34": get("humanoid", "df", "solve_us_median")
        / get("humanoid", "maba", "solve_us_median"),
        "maba_solve_growth_36_to_195": get("snake195", "maba", "solve_us_median")
        / get("snake36", "maba", "solve_us_median"),
        "maba_share_of_humanoid_step": get("humanoid", "maba", "solve_us_median")
        / get("humanoid", "maba", "step_us_median"),
        "humanoid_step_throughput_maba_over_bullet": get("humanoid", "bullet", "step_us_median")
        / get("humanoid", "maba", "step_us_median"),
    }


def format_table(rows: list[dict]) -> str:
    """Rows as a fixed-width text table."""
    head = (f"{'model':10s} {'dof':>4s} {'depth':>5s} {'backend':8s} {'solve_us':>10s} "
            f"{'step_us':>10s}")
    lines = [head]
    for r in rows:
        s = f"{r['solve_us_median']:.1f}" if math.isfinite(r["solve_us_median"]) else "-"
        t = f"{r['step_us_median']:.1f}" if math.isfinite(r["step_us_median"]) else "-"
        lines.append(f"{r['model']:10s} {r['dof']:4d} {r['depth']:5d} {r['backend']:8s} "
                     f"{s:>10s} {t:>10s}")
    return "\n".join(lines)
