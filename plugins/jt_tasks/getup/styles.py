"""Five authored get-up styles (``003`` §5.5: "5 are authored curves designed to imitate various
get-up styles", each presented at 2.5, 5.1 and 7.6 s).

``003`` authored its curves from the mean curves of LAFAN1 clips classified by the strategies of
Bohannon and Lusardi 2004 (Fig. 8: side-sit to half-kneel pivot, quadruped push-up from prone and
from supine, sit-up and roll-over) and shows two of them (Fig. 9); it publishes no control points.
These are ours, designed with the same guide on jt's feature definitions (``features``): standing
is ``(1.35 m, 90°, 95°)`` (the get-up clips end at h 1.33-1.37 m above the ground they rest on, θz 93-99°: a slight forward
lean), supine ``θz ≈ 0``, prone ``θz ≈ π``, lying on a side ``θx`` far from 90°. Every style starts
at a lying posture a rag-doll drop settles near (supine ``(0.12 m, 90°, 5°)``, prone ``(0.20 m,
90°, 165°)``; the 30° rule of §5.2 pairs them with drops) and ends standing. With jt's clamped
splines a curve starts exactly at its first control point and ends at its last.

Each: 9 control points of h (m), θx (deg), θz (deg), the start posture and what the phases are.
"""

from __future__ import annotations

import math

STAND = (1.35, 90.0, 95.0)  #: h (m), θx, θz (deg) every style ends at
SUPINE = (0.12, 90.0, 5.0)  #: where the supine styles start
PRONE = (0.20, 90.0, 165.0)  #: where the prone styles start

#: name -> (h [9] m, θx [9] deg, θz [9] deg, start posture, phases)
STYLES_DEG: dict[str, tuple[list[float], list[float], list[float], str, str]] = {
    "situp_roll": (
        [0.12, 0.14, 0.45, 0.65, 0.55, 0.70, 0.95, 1.25, 1.35],
        [90.0, 90.0, 90.0, 70.0, 60.0, 75.0, 90.0, 90.0, 90.0],
        [5.0, 10.0, 60.0, 90.0, 130.0, 140.0, 120.0, 100.0, 95.0],
        "supine", "sit up (θz to 90°, h to a sitting 0.65 m), roll over onto the knees (θz past 90°, "
                  "the hips tilt), rise (Bohannon and Lusardi's sit-up and roll-over; 003 Fig. 9 left)"),
    "side_sit_kneel_pivot": (
        [0.12, 0.15, 0.35, 0.55, 0.60, 0.80, 0.95, 1.20, 1.35],
        [90.0, 80.0, 55.0, 45.0, 50.0, 65.0, 80.0, 90.0, 90.0],
        [5.0, 20.0, 50.0, 75.0, 85.0, 90.0, 95.0, 95.0, 95.0],
        "supine", "turn onto one hip (θx to 45°) while sitting up, half-kneel, pivot upright and rise "
                  "(side-sit to half-kneel pivot; 003 Fig. 9 right)"),
    "pushup_prone": (
        [0.20, 0.22, 0.40, 0.60, 0.62, 0.75, 1.00, 1.25, 1.35],
        [90.0] * 9,
        [165.0, 165.0, 165.0, 160.0, 150.0, 130.0, 110.0, 98.0, 95.0],
        "prone", "push up onto hands and knees (h to 0.6 m, torso still facing down), walk the hands "
                 "back into a squat (θz down to 110°), stand (quadruped push-up from prone)"),
    "pushup_supine": (
        [0.12, 0.15, 0.20, 0.25, 0.50, 0.62, 0.90, 1.22, 1.35],
        [90.0, 60.0, 30.0, 60.0, 90.0, 90.0, 90.0, 90.0, 90.0],
        [5.0, 45.0, 90.0, 140.0, 160.0, 150.0, 120.0, 100.0, 95.0],
        "supine", "roll over through lying on the side (θx control points down to 30°, the curve to 42°; "
                  "θz through 90°) to prone, then "
                  "the quadruped push-up (quadruped push-up from supine)"),
    "prone_squat": (
        [0.20, 0.25, 0.45, 0.60, 0.70, 0.75, 0.85, 1.15, 1.35],
        [90.0] * 9,
        [165.0, 160.0, 140.0, 120.0, 105.0, 100.0, 100.0, 97.0, 95.0],
        "prone", "press straight up into a deep squat with the torso upright early (θz to 105° by "
                 "mid-motion, h only 0.7 m), hold, then rise (ours: a slow squat rise)"),
}

STYLES = tuple(STYLES_DEG)  #: the authored style names


def authored_styles() -> dict[str, dict]:
    """The styles in ``task.authored``'s form: ``{name: {h, theta_x, theta_z (rad), duration}}``
    (duration 5.1 s, the middle of 003's three; ``task.authored_durations`` presents each at all three)."""
    out = {}
    for name, (h, tx, tz, _, _) in STYLES_DEG.items():
        out[name] = {"h": list(h), "theta_x": [math.radians(v) for v in tx],
                     "theta_z": [math.radians(v) for v in tz], "duration": 5.1}
    return out
