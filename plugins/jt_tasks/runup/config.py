"""The ``task`` group of ``task=runup`` (``000`` §6.1.1): every default declared once, here.

``RunupTask`` reads it, ``RunupEnv``'s spec takes its defaults from it (``toolkit.policy.spec``);
conf/task/runup.yaml names each value's source.
"""

from __future__ import annotations

import dataclasses
from typing import Optional

from toolkit.policy.task import PolicyConfig


@dataclasses.dataclass
class RunupConfig(PolicyConfig):
    """The ``task`` group of ``task=runup`` (conf/task/runup.yaml has each value's source)."""

    name: str = "runup"
    kind: str = "highjump"
    """Highjump: r_G of 000 eq 13 (omega_x, omega_z, v_z); obstacle: 000 eq 14 (omega_x, omega_y, omega_z)."""
    point: dict = dataclasses.field(default_factory=dict)
    """Target features fixed here are not searched."""
    ranges: dict = dataclasses.field(default_factory=dict)
    """{feature: [low, high]}; unset: those of conf/task/<kind>.yaml (ours, enclosing 000 Tables 3-4)."""
    target: dict = dataclasses.field(default_factory=dict)
    """Default targets; unset: the take-off of conf/task/<kind>.yaml (highjump: Fosbury flop, 000 Table 3)."""
    omega_y: Optional[float] = 3.0
    """Rad/s, fixed omega_y target of the high jump (000 §6.1.1)."""
    clip: str = "run"
    """Reference run: pybullet_data humanoid3d_run.txt (000 §6.1.1 used a curved / straight sprint of its own)."""
    foot: str = "right"
    """Take-off foot (as conf/task/highjump.yaml; ours)."""
    n_strides: int = 2
    """The episode ends at the 2nd take-off-foot mid-support after the start (ours; 000 §3 defines the take-off instant)."""
    contact_tol: float = 0.06
    """M: a foot this close to its lowest height is in support (ours, as jt_tasks.takeoff.state.support_phase_time)."""
    foot_clearance: float = 0.002
    """M: the take-off foot's height at take-off in the reference (ours, as the jump env)."""
    check_every: int = 1
    """Substeps between early-termination contact checks (ours: every 600 Hz substep)."""
    w_imitation: float = 0.7
    """W_I of r = w_I r_I + w_G r_G (ours: 000 gives no weights; Peng et al. 2018 use 0.7 in their task examples)."""
    w_goal: float = 0.3
    """W_G (ours; Peng et al. 2018 use 0.3 there)."""
    goal_steps: Optional[float] = None
    """R_G is paid once, at take-off, times this; null: the episode's control steps (ours)."""
    eval_lead: Optional[float] = None
    """S before the take-off foot's mid-support that the final rollout starts; null: n_strides whole cycles (ours)."""
