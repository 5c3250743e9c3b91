"""``task=spacetime``'s parameters: every ``task.*`` default with its source (``002``, Ma et al.
2021, and the authors' code where the paper is silent). ``SpacetimeSpec`` takes the defaults of
the fields it shares with this from here (``toolkit.policy.spec``).
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar, Optional

from toolkit.policy.task import PolicyConfig


@dataclasses.dataclass
class SpacetimeConfig(PolicyConfig):
    """The ``task`` group of ``task=spacetime`` (every default with its source)."""

    #: fields where .inf means "this bound is off" (every other number must be finite)
    NONFINITE_OK: ClassVar[tuple[str, ...]] = ("com_width", "orientation_width", "end_effector_width", "widths",
                                               "width_table")

    name: str = "spacetime"
    """Registry name."""
    clip: str = "run"
    """Reference motion: a pybullet_data humanoid clip (humanoid3d_<clip>.txt) or a path (002 Table 1 motions; ours: run)."""
    loop: Optional[bool] = None
    """Override the clip's Loop flag; null: the file's (every shipped clip wraps; 002 §5: jump and backflip end, ours to choose)."""
    heading_axis: Optional[str] = None
    """Root axis whose ground projection is the heading: x or z; null: z for backflip, roll, crawl, else x (authors' code)."""
    termination: str = "bounds"
    """Bounds: spacetime-bound early termination (002 §3.2 eq 2); contact: the DeepMimic baseline (002 Table 1)."""
    com_width: Any = 0.2
    """M, CoM x/y/z channels, one number or [x, y, z] (002 §5.1; the authors' code: [0.3, 0.2, 0.3])."""
    orientation_width: Optional[float] = 0.7
    """Rad, root and joint angle channels (002 §5.1); null: off."""
    end_effector_width: Optional[float] = 0.5
    """M, ankle and wrist channels (002 §5.1); null: off."""
    widths: dict = dataclasses.field(default_factory=dict)
    """{channel or group (com, orientation, end_effector): width} overrides; null or .inf switches a channel off (002 §5.3.1 style runs)."""
    width_table: list = dataclasses.field(default_factory=list)
    """Phase table: K rows evenly over phase [0, 1], each {channel or group: width} over the widths above (or 22 numbers), linearly interpolated at the clip's phase mod 1 (authors' code); []: the constant widths (002 §5.1; every table the authors ship is constant)."""
    time_limit: float = 20.0
    """S, training episodes are truncated (bootstrapped) here (002 §5.1)."""
    hold_s: float = 0.5
    """S, a non-looping clip is extended by holding its last frame this long (authors' code)."""
    init_phase: Optional[float] = None
    """Start phase of training episodes; null: uniform over [0, 1) (reference state initialisation, 002 §4.2 / DeepMimic)."""
    ground_clearance: float = 0.001
    """M, a start that penetrates the ground is lifted so that its lowest point is this high; other starts and the reference are the clip's own (authors' code: 0.001)."""
    cycle_turn: bool = True
    """A looping clip's next cycle carries on its heading change from first to last frame (walk 0.12 rad, run -0.09), so the heading does not snap back at the seam (ours; the authors' code shifts each cycle by the root's position change only: the heading snaps back at every seam). The walk's 0.12 rad is a yaw jump in its data, not a turn of its path: task.straighten removes it."""
    straighten: bool = False
    """Remove the root's yaw from every frame of a looping clip (each frame faces as the first; pitch, roll, positions, joints kept), so the clip faces the way it travels and cycles do not turn (ours; the shipped walk's root yaw jumps 0.125 rad mid-cycle and ends 0.12 rad from its start while its path goes straight; the authors' walk file has no root rotation at all; 002 and DeepMimic's file: the clip as recorded)."""
    root_orientation: str = "world"
    """Frame of the root's orientation in the observation: world, the reference cycle's frame (the world frame when cycles do not turn), so the policy sees the heading the bounds hold (002 §4.1: every kinematic quantity in the motion-direction frame except the root orientation; authors' code: use_global_root_ori); heading: in the root's own heading frame like the other links (jt before 2026-12, which hides the heading drift that ends the walk by its lateral CoM bound)."""
    velocities: str = "joints"
    """Velocities in the observation after the root's: joints, the joint velocities (ours; 148-D on the humanoid); links, every link's centre-of-mass linear and angular velocity in the heading frame (002 §4.1 "linear velocity v and angular velocity ω of each link"; 210-D, the authors' 197-D state plus the massless base row jt's pose block carries besides the pelvis)."""
    ffc_lead: float = 0.0
    """Control steps by which the FFC's reference pose leads the control step's start (002 and the authors' code: 0, the pose at the start of the step held over its substeps)."""
    ffc_velocity: bool = False
    """The reference's joint velocities at the FFC's time as the PD target velocity (002 and the authors' code: zero target velocity)."""
    eval_starts: int = 4
    """Start phases of Table 1's evaluation, eval_phase + k / eval_starts; survival_s is their mean, survival_min_s the worst (authors' code: the mean over several episodes from random phases; ours: evenly spread, deterministic)."""
    style: list = dataclasses.field(default_factory=list)
    """Style reward terms ([{name: energy, ...}], jt.rewards), multiplied into the reward of 1 (002 §3.3 eqs 4-8)."""
    eval_phase: float = 0.0
    """Start phase of the deterministic evaluation (ours)."""
    eval_time_limit: float = 20.0
    """S, the evaluation asks for this long without falling (002 Table 1: 20 s)."""
    allowed_contacts: Optional[list] = None
    """Link names allowed on the ground in the evaluation and the contact arm (["all"]: any); null: per clip (authors' code: walk feet, cartwheel feet and hands, crawl all but root/chest/neck, roll all)."""
    filmstrip_frames: int = 4
    """Frames of the final rollout's filmstrip (ours)."""
    eval_every: int = 10
    """PPO iterations between evaluations during training, for survival_s vs samples and samples_to_20s (authors' code: every 10; 0: only the final one)."""
    mix: Optional[float] = None
    """Eq 13 weight w_s: reward (1 - w_s) imitation + w_s style in either arm (002 §5.3.1 Table 2: 0.5-0.8); null: survival x style / imitation."""
    importance_sampling: Optional[bool] = None
    """Start segments by eq 11 (002 §4.3.1); null: on with termination=bounds, off (uniform RSI, DeepMimic) with contact."""
    n_segments: int = 10
    """Segments of the clip for eq 11 and eq 12 (002 §4.3.1; authors' code: 10 for the Table 1 motions)."""
    is_uniform: float = 0.2
    """U of eq 11, the share of uniformly drawn segments (002 §4.3.1)."""
    is_average: float = 0.99
    """Running-average factor of each segment's start targets w_k (authors' code; 002 §4.3.1: "average")."""
    is_reading: str = "paper"
    """Eq 11 temperature: paper v = (max - min) / 3 (002 §4.3.1); code v = (max - min) + 0.01 (authors' code)."""
    evolution: bool = False
    """Initial-state evolution, eq 12 (002 §4.3.2, for low-quality references; authors' code: off for every Table 1 motion)."""
    evolution_size: int = 200
    """M, states per segment buffer (002 §4.3.2 leaves m open; authors' code: 200, 100 Atlas, 20 long dances)."""
    evolution_reading: str = "paper"
    """Eq 12: paper exp(-w/v), v = max - min, favours low returns (002 §4.3.2); code exp(3 (w - max) / (gap + 0.01)), favours high, old values x 0.95 (authors' code)."""
    evolution_share: Optional[float] = None
    """Share of starts from a buffer state; null: 1 with the paper reading (002 §4.3.2: starts are drawn from the buffers), 0.8 with the code's (authors' code)."""
    evolution_warmup: Optional[int] = None
    """Iterations before buffer starts begin; null: 0 with the paper reading (002 §4.3.2), 400 with the code's (authors' code)."""

    def sampling_params(self, termination: Optional[str] = None):
        """The ``SamplingParams`` these fields give (readings' defaults filled in)."""
        from jt_tasks.spacetime.sampling import SamplingParams

        code = self.evolution_reading == "code"
        term = self.termination if termination is None else termination
        return SamplingParams(
            importance_sampling=(term == "bounds") if self.importance_sampling is None else bool(self.importance_sampling),
            n_segments=int(self.n_segments), is_uniform=float(self.is_uniform), is_average=float(self.is_average),
            is_reading=str(self.is_reading), evolution=bool(self.evolution), evolution_size=int(self.evolution_size),
            evolution_share=(0.8 if code else 1.0) if self.evolution_share is None else float(self.evolution_share),
            evolution_warmup=(400 if code else 0) if self.evolution_warmup is None else int(self.evolution_warmup),
            evolution_reading=str(self.evolution_reading), decay=0.95 if code else 1.0)

    def check(self) -> None:
        """One-line ``JtError`` for a bad clip, width, channel, heading axis or range."""
        from toolkit.motion.skeletons import HUMANOID
        from toolkit.schema import finite, require

        from jt_tasks.spacetime import bounds as bd
        from jt_tasks.spacetime.reference import load_humanoid_clip

        clip = load_humanoid_clip(self.clip)
        loops = bool(clip.loop) if self.loop is None else bool(self.loop)
        require(not self.straighten or loops, "task.straighten", self.straighten,
                "removes a looping clip's yaw drift and does nothing on a clip that does not loop "
                "(task.loop=false); drop one of them")
        require(self.heading_axis in (None, "x", "z"), "task.heading_axis", self.heading_axis, "x or z (null: per clip)")
        require(self.root_orientation in ("world", "heading"), "task.root_orientation", self.root_orientation,
                "world or heading")
        require(self.velocities in ("joints", "links"), "task.velocities", self.velocities, "joints or links")
        require(self.termination in ("bounds", "contact"), "task.termination", self.termination,
                "bounds (002 §3.2) or contact (the DeepMimic baseline)")
        com = list(self.com_width) if isinstance(self.com_width, (list, tuple)) else self.com_width
        base = bd.widths(HUMANOID, com, self.orientation_width, self.end_effector_width, self.widths)
        bd.width_table(HUMANOID, base, self.width_table)
        for key in ("time_limit", "hold_s", "eval_time_limit"):
            v = getattr(self, key)
            require(finite(v) and (v > 0 or (key == "hold_s" and v >= 0)), f"task.{key}", v, "must be a finite number > 0")
        for key in ("init_phase", "eval_phase"):
            v = getattr(self, key)
            require(v is None or (finite(v) and 0.0 <= v <= 1.0), f"task.{key}", v, "a phase in [0, 1]")
        require(finite(self.ground_clearance) and self.ground_clearance >= 0, "task.ground_clearance",
                self.ground_clearance, "a finite number >= 0 (m)")
        require(finite(self.ffc_lead) and self.ffc_lead >= 0, "task.ffc_lead", self.ffc_lead,
                "a number of control steps >= 0")
        require(int(self.eval_starts) >= 1, "task.eval_starts", self.eval_starts, "an integer >= 1")
        if self.allowed_contacts is not None:
            known = {"base", "all", *HUMANOID.links}
            bad = [n for n in self.allowed_contacts if str(n) not in known]
            require(not bad, "task.allowed_contacts", bad, f"unknown link(s); links: {', '.join(sorted(known))}")
        for t in self.style:
            require(isinstance(t, dict) and "name" in t, "task.style", t, "a list of {name: <jt.rewards term>, ...}")
        require(self.mix is None or (finite(self.mix) and 0.0 <= self.mix <= 1.0), "task.mix", self.mix,
                "null or a weight w_s in [0, 1] (002 eq 13)")
        for key in ("is_reading", "evolution_reading"):
            require(getattr(self, key) in ("paper", "code"), f"task.{key}", getattr(self, key), "paper or code")
        require(int(self.n_segments) >= 1 and int(self.evolution_size) >= 1, "task.n_segments/evolution_size",
                (self.n_segments, self.evolution_size), "integers >= 1")
        for key in ("is_uniform", "is_average", "evolution_share"):
            v = getattr(self, key)
            require(v is None or (finite(v) and 0.0 <= v <= 1.0), f"task.{key}", v, "a number in [0, 1]")
        require(self.evolution_warmup is None or int(self.evolution_warmup) >= 0, "task.evolution_warmup",
                self.evolution_warmup, "null or an iteration count >= 0")
        require(int(self.eval_every) >= 0, "task.eval_every", self.eval_every, "an iteration count >= 0 (0: off)")
        require(self.filmstrip_frames >= 0 and self.filmstrip_width > 0 and self.filmstrip_height > 0,
                "task.filmstrip_frames/width/height", (self.filmstrip_frames, self.filmstrip_width,
                                                       self.filmstrip_height), "frames >= 0, sizes > 0")
