"""Rewards of the run-up task: DeepMimic's imitation reward and the take-off task reward.

Imitation (Peng et al. 2018, "DeepMimic", §6), per control step, simulated vs reference state::

    r_I = 0.65 r_pose + 0.1 r_vel + 0.15 r_ee + 0.1 r_com
    r_pose = exp(-2   Σ_j ||q̂_j ⊖ q_j||²)     rotation angle of each joint (root: world orientation)
    r_vel  = exp(-0.1 Σ_j ||q̇̂_j − q̇_j||²)     joint angular velocities (local; root: world)
    r_ee   = exp(-40  Σ_e ||p̂_e − p_e||²)     hands and feet
    r_com  = exp(-10  ||p̂_c − p_c||²)         whole-body centre of mass (world)

The paper does not say in which frame the end effectors are compared; like DeepMimic's released
code we take them relative to the root, in each character's facing frame (a world-frame error
would punish any drift of the root forty-fold). Everything else is as printed.

Task reward at the take-off instant (``000`` §6.1.1), in the facing frame of ``takeoff.py``::

    high jump (eq 13):  r_G = exp(-1/3 ||ω − ω̄||₁ − 0.7 (v_z − v̄_z)²),  ω̄ = (ω̄_x, 3 rad/s, ω̄_z)
    obstacle  (eq 14):  r_G = exp(-1/3 ||ω − ω̄||₁)
"""

from __future__ import annotations

import math
from typing import Mapping, Optional

import numpy as np

from toolkit.motion import rotations as rot

#: DeepMimic's imitation weights and scales (Peng et al. 2018 §6)
IMITATION_WEIGHTS = {"pose": 0.65, "vel": 0.1, "ee": 0.15, "com": 0.1}
IMITATION_SCALES = {"pose": 2.0, "vel": 0.1, "ee": 40.0, "com": 10.0}
#: take-off features measured at the end of the run-up (names as in ``jt_tasks.takeoff.state``)
MEASURED = ("omega_x", "omega_y", "omega_z", "v_z")
#: the targets of each kind: eq 13 (omega_y fixed, not explored) and eq 14
GOAL_FEATURES = {"highjump": ("omega_x", "omega_z", "v_z"), "obstacle": ("omega_x", "omega_y", "omega_z")}
OMEGA_Y_HIGHJUMP = 3.0  # rad/s, 000 §6.1.1: "We fix the desired root Y angular velocity to 3rad/s"


def pose_error(skeleton, q_sim: np.ndarray, q_ref: np.ndarray) -> float:
    """Σ_j (rotation angle of joint j's difference)² over the root (world) and every joint, rad²."""
    err = float(rot.quat_angle(q_ref[3:7], q_sim[3:7]) ** 2)
    for j, s in zip(skeleton.joints, skeleton.q_slices.values()):
        a, b = q_ref[7:][s], q_sim[7:][s]
        d = rot.quat_angle(a, b) if j.kind == "spherical" else abs(float(a[0] - b[0]))
        err += float(d) ** 2
    return err


def velocity_error(qd_sim: np.ndarray, qd_ref: np.ndarray) -> float:
    """Σ_j ||ω̂_j − ω_j||² over the root angular velocity (world) and the joints (local), (rad/s)²."""
    d = np.asarray(qd_ref[3:], dtype=float) - np.asarray(qd_sim[3:], dtype=float)
    return float(d @ d)


def imitation_terms(skeleton, q_sim: np.ndarray, qd_sim: np.ndarray, ee_sim: np.ndarray, com_sim: np.ndarray,
                    q_ref: np.ndarray, qd_ref: np.ndarray, ee_ref: np.ndarray, com_ref: np.ndarray) -> dict[str, float]:
    """DeepMimic's four imitation terms and their weighted sum ``imitation`` (Peng et al. 2018 §6).

    Args:
        skeleton: the character's joint table (``toolkit.motion.skeletons``).
        q_sim, q_ref: positions ``(n_q,)``.
        qd_sim, qd_ref: velocities ``(n_dof,)``.
        ee_sim, ee_ref: end effectors relative to the root in the facing frame ``(n_ee, 3)``.
        com_sim, com_ref: centres of mass in the world ``(3,)``.

    Returns:
        ``{"pose", "vel", "ee", "com", "imitation"}``, each in ``[0, 1]``.
    """
    s = IMITATION_SCALES
    de = np.asarray(ee_ref, dtype=float) - np.asarray(ee_sim, dtype=float)
    dc = np.asarray(com_ref, dtype=float) - np.asarray(com_sim, dtype=float)
    terms = {
        "pose": math.exp(-s["pose"] * pose_error(skeleton, q_sim, q_ref)),
        "vel": math.exp(-s["vel"] * velocity_error(qd_sim, qd_ref)),
        "ee": math.exp(-s["ee"] * float(np.sum(de * de))),
        "com": math.exp(-s["com"] * float(dc @ dc)),
    }
    terms["imitation"] = sum(IMITATION_WEIGHTS[k] * terms[k] for k in IMITATION_WEIGHTS)
    return terms


def measure(q: np.ndarray, qd: np.ndarray) -> dict[str, float]:
    """Take-off features of a state: root ω (x, y, z) and v_z in the facing frame (``takeoff.py``)."""
    from jt_tasks.takeoff.state import facing_velocities

    v, w = facing_velocities(q, qd)
    return {"omega_x": float(w[0]), "omega_y": float(w[1]), "omega_z": float(w[2]), "v_z": float(v[2])}


def goal_targets(kind: str, target: Mapping[str, float],
                 omega_y: Optional[float] = OMEGA_Y_HIGHJUMP) -> dict[str, float]:
    """The targets r_G compares with: the explored features, plus ``omega_y`` for the high jump."""
    if kind not in GOAL_FEATURES:
        from toolkit.errors import JtError

        raise JtError(f"runup: kind={kind!r}: highjump (000 eq 13) or obstacle (000 eq 14)")
    missing = [k for k in GOAL_FEATURES[kind] if k not in target]
    if missing:
        from toolkit.errors import JtError

        raise JtError(f"runup: target feature(s) {', '.join(missing)} missing for kind={kind}")
    out = {k: float(target[k]) for k in GOAL_FEATURES[kind]}
    if kind == "highjump":
        out["omega_y"] = float(OMEGA_Y_HIGHJUMP if omega_y is None else omega_y)
    return out


def goal_reward(kind: str, achieved: Mapping[str, float], targets: Mapping[str, float]) -> float:
    """r_G of ``000`` eq 13 (``highjump``) or eq 14 (``obstacle``).

    Args:
        kind: ``highjump`` or ``obstacle``.
        achieved: measured features (``measure``).
        targets: ``goal_targets(kind, ...)``: ω̄ (all three components) and, for eq 13, v̄_z.
    """
    l1 = sum(abs(float(achieved[k]) - float(targets[k])) for k in ("omega_x", "omega_y", "omega_z"))
    expo = -l1 / 3.0
    if kind == "highjump":
        expo -= 0.7 * (float(achieved["v_z"]) - float(targets["v_z"])) ** 2
    return math.exp(expo)
