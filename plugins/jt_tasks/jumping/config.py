"""The jumping tasks' ``task`` groups (``000`` §6.1): the high jump's defaults, the obstacle and
long jump's changes, and their range checks (``Config.check``, at composition)."""

from __future__ import annotations

import dataclasses
import os
from typing import Optional

from toolkit.policy.task import PolicyConfig

FOSBURY = {"alpha": -0.05, "omega_x": -3.0, "omega_z": 1.0, "v_z": -2.40}  # 000 Table 3


@dataclasses.dataclass
class JumpConfig(PolicyConfig):
    """Parameters shared by the jumping tasks (the ``task`` group); the high jump's defaults.

    The task's other choices are Hydra defaults of ``conf/task/<task>.yaml``: P-VAE actions
    (000 §4.2), the product reward (000 eqs 2, 15, 16), the bar-height curriculum (000 §6.1.3) and
    the dense SPD backend (ours: the same torques as MABA, faster for 34 DoF).
    """

    name: str = "highjump"
    """Registry name."""
    stage: int = 1
    """1: take-off exploration (000 §5.1); 2: novel policy seeking (000 §5.2; with reward=<task>_stage2)."""
    init: str = ""
    """Stage 2: Stage-1 run id (outer run or nested evaluation), or its folder / ppo.h5 (000 §5.2)."""
    init_eval: int = -1
    """Stage 2, outer init run: evaluation index (jt.eval_index); -1: the best one (ours)."""
    policy_features: list = dataclasses.field(default_factory=list)
    """Stage 2: extra root orientations (x, y, z, w, suite frame) of earlier policies for Π (000 eq 12)."""
    point: dict = dataclasses.field(default_factory=dict)
    """Take-off features fixed here are not searched."""
    ranges: dict = dataclasses.field(default_factory=lambda: {
        "alpha": [-0.5, 2.5], "omega_x": [-3.0, 3.0], "omega_z": [-3.0, 3.0], "v_z": [-2.5, -0.5]})
    """Search box ``{feature: [low, high]}``: ours, enclosing 000 Table 3 (the paper gives no ranges);
    alpha (rad) turns the wall line x sin(a) - z cos(a) in the facing frame (000 App. A), omega_x,
    omega_z (rad/s) in the facing frame (000 §6.1.1), v_z (m/s)."""
    takeoff: dict = dataclasses.field(default_factory=lambda: dict(FOSBURY))
    """Defaults of the searched features: the Fosbury flop take-off state (000 Table 3)."""
    takeoff_from: str = ""
    """A task=runup run id / folder / takeoff_state.h5 to start from (000 §6.1.1); "": the run
    clip's take-off frame with the features imposed (docs/highjump.md)."""
    distance: float = 0.9
    """m from the take-off root to the bar plane / obstacle (ours)."""
    max_time_to_bar: Optional[float] = None
    """s, high jump only: search only take-off states whose horizontal root velocity carries the
    root to the bar plane within this time (``distance / v_n <= t``, ``v_n`` the speed along the
    bar's normal, set by alpha and v_z): a known constraint that bds and random keep to, rmoo and
    bsoo refuse and single ignores (it evaluates its given point) (ours; 000 gives no search box;
    docs/highjump.md "Deviations from the paper"). null: the whole box (the paper)."""
    obstacle_height: float = 0.5
    """m, the obstacle jump's box (000 §6.1: 50 cm); unused by the high jump; 0: the long jump."""
    mat_height: float = 0.3
    """m, the rigid landing block (000 §6.1 gives no size; ours)."""
    clip: str = "run"
    """Reference run: pybullet_data humanoid3d_run.txt (000 §6.1.1 used a curved sprint)."""
    foot: str = "right"
    """Take-off foot (ours; the outer foot of a Fosbury flop with the bar on the left)."""
    omega_y: Optional[float] = 3.0
    """rad/s, the high jump's fixed facing-frame omega_y (000 §6.1.1); None: explored / kept."""
    v_y: Optional[float] = 2.06
    """m/s vertical root speed at take-off, the "jumping intention" of the authors' run-up (000 §8);
    ours: humanoid3d_jump.txt's lift-off speed (DeepMimic's run has none); None: the run clip's."""
    time_limit: float = 2.0
    """s after take-off (000 §6.1)."""
    safe_margin: float = 0.2
    """m: a landing counts with every part this far from the wall (000 §6.1)."""
    check_every: int = 1
    """Substeps between contact checks (ours: every 600 Hz substep)."""
    distinct_threshold: float = 0.5
    """rad: Stage-1 features closer than this count as one strategy (ours)."""
    final_fallback: bool = True
    """Ours: when the deterministic jump at the reached bar never crosses its plane (a budget that
    ends right after the curriculum raised the bar, before the policy learnt the new height),
    roll it out again one Δz lower, down to z_min, and report the first that crosses:
    ``bar_height_reached`` is that bar, ``bar_height_trained`` the curriculum's."""

    def check(self) -> None:
        """Range checks (one ``JtError`` line each)."""
        from toolkit.schema import finite, require

        require(self.stage in (1, 2), "task.stage", self.stage,
                "1 (take-off exploration) or 2 (novel policy seeking)")
        for key, box in (self.ranges or {}).items():
            pair = [box] if isinstance(box, str) or not hasattr(box, "__len__") else list(box)
            require(len(pair) == 2 and finite(pair[0]) and finite(pair[1]) and float(pair[0]) < float(pair[1]),
                    f"task.ranges.{key}", box, "needs finite [low, high] with low < high")
        for key in ("distance", "time_limit", "distinct_threshold"):
            require(finite(getattr(self, key)) and getattr(self, key) > 0, f"task.{key}", getattr(self, key),
                    "must be a finite number > 0")
        require(self.max_time_to_bar is None or (finite(self.max_time_to_bar) and self.max_time_to_bar > 0),
                "task.max_time_to_bar", self.max_time_to_bar, "must be a number of seconds > 0 (or null: no constraint)")
        require(self.max_time_to_bar is None or self.name == "highjump", "task.max_time_to_bar", self.max_time_to_bar,
                f"is for task=highjump (task={self.name} runs straight at its obstacle): leave it null")
        for key in ("obstacle_height", "mat_height", "safe_margin"):
            require(finite(getattr(self, key)) and getattr(self, key) >= 0, f"task.{key}", getattr(self, key),
                    "must be a finite number >= 0")
        require(self.foot in ("left", "right"), "task.foot", self.foot, "left or right")
        if os.path.sep not in self.clip:  # a shipped clip by name (a path is read when the env starts)
            from toolkit.motion.skeletons import humanoid_clip_paths

            names = [os.path.basename(q)[len("humanoid3d_"):-len(".txt")] for q in humanoid_clip_paths()]
            require(self.clip in names, "task.clip", self.clip, f"one of {', '.join(names)} (or a clip file's path)")
        else:
            require(os.path.isfile(self.clip), "task.clip", self.clip, "no such file")
        require(self.check_every >= 1, "task.check_every", self.check_every, "must be >= 1")
        require(self.filmstrip_frames >= 0 and self.filmstrip_width > 0 and self.filmstrip_height > 0,
                "task.filmstrip_frames/width/height", (self.filmstrip_frames, self.filmstrip_width,
                                                       self.filmstrip_height), "frames >= 0, sizes > 0")


@dataclasses.dataclass
class ObstacleConfig(JumpConfig):
    """The obstacle jump's group (000 §6.1): the obstacle_width curriculum and reward."""

    name: str = "obstacle"
    """Registry name."""
    ranges: dict = dataclasses.field(default_factory=lambda: {
        "omega_x": [-3.0, 3.0], "omega_y": [-3.0, 3.0], "omega_z": [-3.0, 4.0]})
    """Search box of the take-off root angular velocity (rad/s, facing frame, 000 §6.1.1): ours,
    enclosing 000 Table 4."""
    takeoff: dict = dataclasses.field(default_factory=lambda: {"omega_x": 0.0, "omega_y": 0.0, "omega_z": 1.0})
    """Defaults of the searched features: the Straddle take-off state (000 Table 4)."""
    omega_y: Optional[float] = None
    """Explored by the obstacle jump (000 §6.1.1), so not fixed."""


@dataclasses.dataclass
class LongJumpConfig(ObstacleConfig):
    """The long jump's group: an obstacle jump over an obstacle of height 0 (a gap before the mat)."""

    name: str = "longjump"
    """Registry name."""
    obstacle_height: float = 0.0
    """No box: jump the width onto the mat (jt variation)."""
