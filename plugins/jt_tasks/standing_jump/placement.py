"""Flight predictions and foot placement for the jump controller (``004`` §3.1).

"While in air, a simple time prediction strategy determines the time taken to reach the peak
point of the motion ... During this phase [fall], again, a simple prediction strategy determines
both the approximate time and location of touch-down. Inverse kinematics is used to target the
feet to their predicted touch-down location."
"""

from __future__ import annotations

import math
from typing import Callable


def time_to_apex(vz: float, gravity: Callable[[float], float], t0: float = 0.0, dt: float = 0.002,
                 horizon: float = 5.0) -> float:
    """Time until a vertical velocity ``vz`` (m/s) reaches zero under gravity ``gravity(t0 + t)``.

    Gravity may vary (the supernatural assist ramps it back to -9.8 m/s²), so the ballistic
    equation is integrated with step ``dt`` (s) for at most ``horizon`` seconds.
    """
    t, v = 0.0, vz
    while v > 0.0 and t < horizon:
        v += gravity(t0 + t) * dt
        t += dt
    return t


def time_to_touchdown(height: float, vz: float, g: float = 9.8) -> float:
    """Time (s) for a point ``height`` m above the ground, moving up at ``vz`` m/s, to land."""
    return (vz + math.sqrt(max(vz * vz + 2.0 * g * max(height, 0.0), 0.0))) / g


def leg_ik(dx: float, pelvis_pitch: float, hip: float, knee: float, thigh: float, shank: float,
           knee_min: float, knee_max: float, hip_limit: float) -> tuple[float, float]:
    """Hip and knee angles that put the ankle ``dx`` m ahead of the hip (planar two-link IK).

    Knee first: with the hip at ``hip`` the knee is solved so the ankle reaches ``dx`` (moving the
    light shank barely counter-rotates the trunk in flight). If that needs a knee outside
    ``[knee_min, knee_max]`` the knee is clamped and the whole leg is rotated about the hip, by at
    most ``hip_limit`` rad.

    Args:
        dx: wanted horizontal ankle position relative to the hip (m, + forward).
        pelvis_pitch: pelvis pitch about +y (rad).
        hip: nominal hip flexion (rad); the hip axis is -y, so thigh pitch = pelvis pitch - hip.
        knee: nominal knee flexion (rad); the knee axis is +y, so shank pitch = thigh pitch + knee.
        thigh: thigh length, hip to knee (m).
        shank: shank length, knee to ankle (m).
        knee_min: least knee flexion (rad).
        knee_max: most knee flexion (rad).
        hip_limit: largest hip change (rad).

    Returns:
        ``(hip, knee)`` flexion angles (rad).
    """
    phi_t = pelvis_pitch - hip  # a segment (0, -L) pitched by phi reaches x = -L sin(phi)
    s = (-dx - thigh * math.sin(phi_t)) / shank
    if abs(s) <= 1.0:
        k = math.asin(s) - phi_t
        if knee_min <= k <= knee_max:
            return hip, k
    k = min(max(math.asin(min(max(s, -1.0), 1.0)) - phi_t, knee_min), knee_max)
    phi_s = phi_t + k
    x = -thigh * math.sin(phi_t) - shank * math.sin(phi_s)
    z = -thigh * math.cos(phi_t) - shank * math.cos(phi_s)
    rho = math.hypot(x, z)
    gamma = math.atan2(-x, -z)  # leg pitch: (x, z) = -rho (sin gamma, cos gamma)
    delta = math.asin(min(max(-dx / rho, -1.0), 1.0)) - gamma  # extra leg pitch needed
    return hip + min(max(-delta, -hip_limit), hip_limit), k
