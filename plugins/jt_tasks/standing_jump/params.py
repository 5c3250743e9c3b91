"""The 34 free parameters of the standing-jump controller (``004`` §3) and the fixed poses.

``004`` §3: "The free parameters consist of the joint target angles for the hips, knees, back,
abdominal region, shoulder and elbows for all phases; joint target angles for the ankles for take
off and rising phase; and the external force parameters. Thus we optimize for 34 free parameters."

Read literally that is 6 joints × 5 phases + 2 ankle targets + 2 assist parameters = 34, with the
five phases that have targets of their own: crouch, take-off, rise (the airborne rising phase,
"flight"), fall and land. The stand phase holds the fixed standing pose ``STAND``, which is also
where the landing phase ends up ("the target angles for this phase raise the character to attain
a standing posture", §3.1).

Angles are radians, anatomically signed (positive = flexion; see ``model``). ``back`` and the
ankles are world-frame targets, as the paper servos "the feet, pelvis and upper torso" in world
coordinates: ``back`` is the forward lean of the chest from vertical, the ankle target the pitch of
the foot from flat (positive = toes up), and in the stance phases (crouch, take-off, land) ``hip``
is the forward lean of the pelvis, servoed through the stance hips; in flight (rise, fall) ``hip``
is the hip flexion angle. The other joints are local joint angles.

The defaults are the seed controller: a low jump (head apex 1.75 m) that lands in place and stands
up, designed by hand and refined with short CMA-ES runs (the paper starts from a manually designed
controller, §3; docs/standing_jump.md).
"""

from __future__ import annotations

from toolkit.interfaces.searcher import Param, Space

PHASES = ("crouch", "takeoff", "rise", "fall", "land")
"""Phases with searched targets, in order (stand comes before crouch and has fixed targets)."""

JOINTS = ("hip", "knee", "back", "abs", "shoulder", "elbow")
"""Joint classes with a target in every searched phase."""

BOUNDS = {
    "hip": (-0.5, 2.2),
    "knee": (0.0, 2.4),
    "back": (-0.4, 1.2),  # world-frame chest lean
    "abs": (-0.4, 1.0),
    "shoulder": (-1.2, 3.1),
    "elbow": (0.0, 2.4),
    "ankle": (-1.0, 0.3),  # world-frame foot pitch (toes up +)
}

# the seed controller: hand-designed, then refined with a short CMA-ES run for a robust low jump
# (see docs/standing_jump.md, 'The seed controller')
SEED = {
    "crouch": {"hip": 0.505, "knee": 1.967, "back": 0.417, "abs": 0.101, "shoulder": -1.08, "elbow": 0.435},
    "takeoff": {"hip": -0.041, "knee": 0.002, "back": -0.008, "abs": -0.004, "shoulder": 2.596, "elbow": 0.115},
    "rise": {"hip": 0.581, "knee": 0.043, "back": 0.035, "abs": 0.205, "shoulder": 2.049, "elbow": 0.379},
    "fall": {"hip": 0.462, "knee": 1.392, "back": 0.28, "abs": 0.398, "shoulder": 0.953, "elbow": 0.825},
    "land": {"hip": 0.07, "knee": 1.418, "back": 0.757, "abs": 0.121, "shoulder": 0.628, "elbow": 0.37},
}
SEED_ANKLE = {"takeoff": -0.673, "rise": 0.001}

STAND = {"hip": 0.0, "knee": 0.05, "back": 0.05, "abs": 0.0, "shoulder": 0.0, "elbow": 0.2,
         "ankle": 0.0, "wrist": 0.0, "neck": 0.0, "head": 0.0}
"""Fixed standing pose (stand phase, and the end of the land phase)."""

NATURAL_GRAVITY = -9.8
"""Normal gravity along z, m/s² (``004`` §3.3)."""

GRAVITY_BOUNDS = (-12.0, 6.0)
"""Range of the take-off gravity parameter (m/s²). Values at or below -9.8 all mean no assist (the
range below -9.8 is a dead zone that makes exactly-natural controllers easy to reach); ``004``
Table 3 lists take-off gravities up to +4.23 m/s² (pointing up)."""

ASSIST_TIME_BOUNDS = (0.0, 1.0)
"""Range of the assist duration (s); ``004`` Tables 2–3 list 0.27–0.82 s."""


def param_names() -> list[str]:
    """The 34 parameter names, in search-vector order."""
    names = [f"{ph}_{j}" for ph in PHASES for j in JOINTS]
    names += [f"{ph}_ankle" for ph in SEED_ANKLE]
    return names + ["takeoff_gravity", "assist_time"]


def space(default_gravity: float = -11.0, default_assist_time: float = 0.5) -> Space:
    """The search box: 30 phase targets, 2 ankle targets, 2 assist parameters (``004`` §3).

    Args:
        default_gravity: default take-off gravity parameter (natural: anything ≤ -9.8).
        default_assist_time: default assist duration (irrelevant while the gravity is natural).
    """
    params = []
    for ph in PHASES:
        for j in JOINTS:
            lo, hi = BOUNDS[j]
            params.append(Param(f"{ph}_{j}", lo, hi, SEED[ph][j]))
    for ph, v in SEED_ANKLE.items():
        lo, hi = BOUNDS["ankle"]
        params.append(Param(f"{ph}_ankle", lo, hi, v))
    params.append(Param("takeoff_gravity", *GRAVITY_BOUNDS, default_gravity))
    params.append(Param("assist_time", *ASSIST_TIME_BOUNDS, default_assist_time))
    return Space(tuple(params))


def phase_targets(point: dict[str, float]) -> dict[str, dict[str, float]]:
    """Per-phase targets ``{phase: {joint class: angle}}`` from a point; missing names take the seed.

    Values outside the bounds are clipped to them. Every phase gets an ``ankle`` entry: the searched
    one for take-off and rise, a flat foot (0) otherwise.
    """
    out: dict[str, dict[str, float]] = {"stand": dict(STAND)}
    for ph in PHASES:
        t = {}
        for j in JOINTS:
            lo, hi = BOUNDS[j]
            t[j] = min(max(float(point.get(f"{ph}_{j}", SEED[ph][j])), lo), hi)
        lo, hi = BOUNDS["ankle"]
        t["ankle"] = min(max(float(point.get(f"{ph}_ankle", SEED_ANKLE.get(ph, 0.0))), lo), hi)
        for j in ("wrist", "neck", "head"):
            t[j] = STAND[j]
        out[ph] = t
    return out


def assist(point: dict[str, float], deadzone: float = 0.05, min_time: float = 1e-3) -> tuple[float, float]:
    """Effective take-off gravity and assist duration (``004`` §3.3), exactly natural when small.

    The gravity parameter is clipped to at least -9.8 m/s²; an assist ``g0 + 9.8`` below
    ``deadzone`` m/s², or a duration below ``min_time`` s, is no assist at all: the result is then
    exactly ``(-9.8, 0.0)`` and the simulation applies no external force.

    Returns:
        ``(g0, duration)``: gravity along z right after take-off (m/s²) and the ramp duration (s).
    """
    g0 = max(float(point.get("takeoff_gravity", GRAVITY_BOUNDS[0])), NATURAL_GRAVITY)
    g0 = min(g0, GRAVITY_BOUNDS[1])
    dur = min(max(float(point.get("assist_time", 0.0)), 0.0), ASSIST_TIME_BOUNDS[1])
    if g0 - NATURAL_GRAVITY < deadzone or dur < min_time:
        return NATURAL_GRAVITY, 0.0
    return g0, dur
