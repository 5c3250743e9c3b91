"""Fixed (not searched) timing and feedback settings of the standing-jump controller."""

from __future__ import annotations

import dataclasses


@dataclasses.dataclass
class Timing:
    """Phase timing and feedback gains of the controller (``004`` §3.1 gives none; ours).

    Attributes:
        stand_time: time in the stand phase before the crouch (s).
        crouch_time: time in the crouch phase before take-off (s).
        crouch_ramp: target ramp duration into the crouch (s).
        takeoff_ramp: target ramp duration into the take-off pose (s).
        takeoff_max: longest take-off phase before the jump counts as "no take-off" (s).
        liftoff_time: time without foot contact that counts as lift-off (s).
        land_absorb: target ramp into the landing pose after touch-down (s).
        land_rise: ramp from the landing pose to the standing pose (s).
        land_hold_max: longest hold in the landing pose before rising regardless (s).
        settle_speed: the character rises once the CoM is slower than this (m/s) ...
        settle_offset: ... and closer than this to the balance point (m).
        stand_hold: time standing after the rise before the episode ends (s).
        vf_kp: virtual-force stiffness on the CoM's horizontal position (N/m).
        vf_kd: virtual-force damping on the CoM's horizontal velocity (N s/m).
        vf_kd_land: landing damping that removes the horizontal momentum (N s/m).
        balance_point: where along the foot (heel 0 → toe 1) the CoM is held.
        takeoff_balance_point: the same during take-off (towards the toes, where the push-off is).
        cop_margin: how far inside the sole's ends the stance ankles keep the centre of pressure (m).
        takeoff_cop_margin: how far from the CoM the push-off may move the centre of pressure (m).
        hip_balance_kp: landing pelvis-lean feedback on the CoM's lead over the balance point (rad/m).
        hip_balance_kd: the same on the CoM's horizontal velocity (rad s/m).
        ik_limit: largest hip correction the fall-phase foot-placement IK may apply (rad).
        ik_knee_min: least knee flexion the IK lands with (rad).
        ik_knee_max: most knee flexion the IK uses (rad).
        landing_height: CoM height assumed for the landing's capture point (m).
        gains_scale: factor on every PD gain.
    """

    stand_time: float = 0.2
    crouch_time: float = 0.7
    crouch_ramp: float = 0.511
    takeoff_ramp: float = 0.247
    takeoff_max: float = 0.6
    liftoff_time: float = 0.01
    land_absorb: float = 0.12
    land_rise: float = 0.9
    land_hold_max: float = 0.8
    settle_speed: float = 0.1
    settle_offset: float = 0.04
    stand_hold: float = 0.4
    vf_kp: float = 2500.0
    vf_kd: float = 400.0
    vf_kd_land: float = 600.0
    balance_point: float = 0.45
    takeoff_balance_point: float = 1.085
    cop_margin: float = 0.02
    takeoff_cop_margin: float = 0.02
    hip_balance_kp: float = 2.0
    hip_balance_kd: float = 0.5
    ik_limit: float = 0.6
    ik_knee_min: float = 0.3
    ik_knee_max: float = 1.8
    landing_height: float = 0.75
    gains_scale: float = 1.0
