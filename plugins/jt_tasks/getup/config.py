"""The ``task`` group of ``task=getup`` (``003``; docs/getup.md): every default with its source.

``jt run task=getup --cfg`` prints every value; ``GetupConfig.check`` turns each mistake into one
``JtError`` line with the valid choices.
"""

from __future__ import annotations

import dataclasses
from typing import Optional

from jt_tasks.getup.curves import REFERENCE
from jt_tasks.getup.styles import STYLES as AUTHORED_STYLES
from jt_tasks.getup.terrain import REGIONS, TerrainSpec
from toolkit.policy.task import PolicyConfig


@dataclasses.dataclass
class GetupConfig(PolicyConfig):
    """The ``task`` group of ``task=getup`` (``jt run task=getup --cfg`` prints every value)."""

    name: str = "getup"
    """Registry name."""
    curves: list[str] = dataclasses.field(
        default_factory=lambda: ["facedown", "facedown_mirror", "faceup", "faceup_mirror", *AUTHORED_STYLES])
    """Training curves: reference curves of the DeepMimic get-up clips (and mirrors), the 5 built-in authored styles (jt_tasks.getup.styles, docs/getup.md) or names in authored (003 §5.5: 13 reference + 5 authored x 3 durations = 28; ours: 4 + 5 x 3 = 19)."""
    authored: dict = dataclasses.field(default_factory=dict)
    """More authored curves, or overrides of the built-in styles: {name: {h: [9], theta_x: [9], theta_z: [9] (rad), duration: s}} (003 §4.3, §5.5)."""
    authored_durations: list[float] = dataclasses.field(default_factory=lambda: [2.5, 5.1, 7.6])
    """S; each authored curve once per duration (003 §5.5: 2.5, 5.1, 7.6 s); empty: its own duration (5.1 s for the built-in styles)."""
    n_control: int = 9
    """Control points per curve (003 §4.1: "nine control points are sufficient")."""
    extraction: str = "sample"
    """Reference curves: sample (003 §4.1, the features at 9 instants) or lstsq (ours: a least-squares fit)."""
    clamped: bool = True
    """Clamped end knots, uniform inside (ours, jt's splines: the curve starts and ends at its end points); false: unclamped cardinal."""
    t_stand: float = 3.0
    """S of standing after T in every episode (003 §5.6: T_stand = 3 s)."""
    stand_pose: str = "clip"
    """The standing starts' pose and eq 9's neutral pose q̂: clip (the facedown clip's final frame, a standing pose from a reference clip as 003 §5.2) or symmetric (ours: that frame with the right leg the mirror image of the left and both soles flat on the ground; held by PD the clip's frame falls in 1.2 s and no sagittal ankle feedback keeps it up, the symmetric one stands with it: docs/getup.md)."""
    p_standing: float = 0.1
    """Share of episodes starting standing (003 §5.2 "necessary"; the share is ours)."""
    p_fallen: float = 0.3
    """Share of episodes starting from a rag-doll state (003 §5.2; the share is ours); the rest start at the curve's clip's first pose (003 §5.5)."""
    rsi: float = 0.0
    """Share of clip starts that begin at a uniformly random time of the clip instead of its first pose, the curve's clock set to that time (reference state initialisation, Peng et al. 2018; ours, not 003: experiment=laptop, docs/getup.md)."""
    rsi_from: float = 0.0
    """Fraction of the clip where starts inside it (``rsi``) begin: drawn in [rsi_from · T, T] (ours; 0: the whole clip); with ``rsi_step`` > 0 the front of a reverse curriculum (``jt_tasks.getup.reverse``, docs/getup.md)."""
    rsi_step: float = 0.0
    """How far the front moves back each time the newest band of starts, [rsi_from, rsi_from + rsi_step) of the clip, succeeds (ours; 0: a fixed window)."""
    rsi_success: float = 0.5
    """Success share of the band's last ``rsi_episodes`` training episodes that moves the front (ours)."""
    rsi_episodes: int = 32
    """Training episodes from the band that share is measured over (ours)."""
    start_noise: float = 0.0
    """Rad, joint perturbation (``initial.perturb_joints``) of every training clip start (ours; 0 = the clip's pose as 003 §5.5)."""
    n_fallen: int = 8
    """Rag-doll states generated per evaluation (ours)."""
    fallen_styles: list[str] = dataclasses.field(default_factory=lambda: ["prone", "supine"])
    """Rag-doll drop postures (003 §5.2: prone or supine)."""
    fallen_seed: int = 0
    """Seed of the rag-doll generator (ours)."""
    drop_height: float = 0.6
    """M, lowest point at release (ours)."""
    drop_perturb: float = 0.3
    """Rad, random joint perturbation of the drop pose (ours)."""
    ragdoll_kd: float = 1.0
    """N m s/rad, joint damping of the passive rag-doll (ours; 003: "passive")."""
    settle_max: float = 3.0
    """S allowed to come to rest (ours; drops settle within 3 s, notes)."""
    rest_speed: float = 0.05
    """At rest when every generalised speed is below this (ours)."""
    drop_hz: Optional[float] = 120.0
    """Hz, simulation rate of the rag-doll drops (ours: a passive rag-doll settles alike at 60-600 Hz, and 5x fewer substeps than the env's 600 Hz make drops cheap); null: the env's."""
    curve_match_deg: float = 30.0
    """A rag-doll start takes a curve whose start torso angles are within this (003 §5.2: 30°)."""
    r_task_min: float = 0.1
    """Early termination when r_task stays below this (003 §5.3)."""
    sustain: float = 0.3
    """S an early-termination condition must last (003 §5.3: 300 ms)."""
    head_grace: float = 1.0
    """S after a start with the head on the floor (supine, rag-doll) during which head contacts do not count (ours; 003 §5.3 has none)."""
    friction: Optional[float] = 1.0
    """Ground and link friction set on the simulator (003 §3.2: mu = 1.0); null: the sim group's."""
    success_height: float = 0.8
    """Standing = neck height >= this x p_h(1) (ours; 003 §6.3 gives no threshold)."""
    success_window: float = 1.0
    """S standing at the end of the episode that make a success (ours)."""
    heightmap_n: int = 5
    """Height-map samples per side (003 §3.3.2: 5 x 5)."""
    heightmap_spacing: float = 0.25
    """M between height-map samples (003 §3.2: 25 cm over 1 m)."""
    terrain: Optional[dict] = dataclasses.field(default_factory=lambda: TerrainSpec().to_dict())
    """The terrain world (003 §3.2, §5.4, Fig. 3; jt_tasks.getup.terrain): four size x size m regions flat/easy/medium/hard along x, each harder one half rough (1 m tiles, 003 §3.2; heights uniform in [0, roughness] m, ours) and half sloped (a triangle wave of slope_deg, the steepest 30° as 003 §6.5; the others ours), seeded; null = flat ground only (a mapping is merged into the default terrain, so {} changes nothing)."""
    train_regions: str = "curriculum"
    """Regions with training rag-doll states: curriculum (all four when curriculum=terrain, else flat only) or flat (ours)."""
    eval_regions: list[str] = dataclasses.field(default_factory=lambda: list(REGIONS))
    """Regions of the Table 1 evaluation (003 §6.3, Table 1: flat, easy, medium, hard)."""
    eval_locations: int = 100
    """Rag-doll drops at seeded locations per evaluated region, one deterministic get-up each (003 §6.3: 100 terrain locations)."""
    eval_seed: int = 1
    """Seed of the evaluation's drops and locations (ours; differs from fallen_seed so they are not the training states)."""
    natural_terms: list[str] = dataclasses.field(default_factory=lambda: ["naturalness"])
    """Reward terms that make r_natural (003 eq 2); the others multiply to r_task (eq 4)."""
    eval_curve: str = "facedown"
    """Curve of the deterministic rollout (from its clip's first pose)."""
    eval_episodes: int = 4
    """Deterministic evaluation get-ups (the rollout, then the other curves' clip starts and rag-doll states in turn) giving success_rate (ours)."""
    eval_clip_starts: int = 0
    """Deterministic get-ups from the clips' first poses with ``eval_start_noise`` (seeded, one seed per episode, the clip curves in turn) at the end of training: ``success_clip`` (issue 29's stage 1; ours; 0: none)."""
    eval_start_noise: float = 0.05
    """Rad, joint perturbation of those starts and of the evaluations during training (ours)."""
    eval_every: int = 0
    """PPO iterations between evaluations during training (0: none): ``eval_clip_during`` deterministic get-ups from perturbed clip starts, as ``(samples, success, got_up)`` rows in ``extra["eval_history"]`` (ours)."""
    eval_clip_during: int = 8
    """Deterministic get-ups per evaluation during training (the clip curves in turn)."""
    time_scale: float = 1.0
    """Default of the searched point: every curve's T times this (003 §4.3)."""
    ffc_lead: int = 0
    """With ``action=ffc_fbc`` (a feed-forward under the policy, ours, not 003: docs/getup.md): control steps the clip pose of the feed-forward target leads the curve's clock (002 §4.2: 0; spacetime's experiment=laptop: 1)."""
    ffc_hold: str = "clip"
    """With ``action=ffc_fbc``, what the feed-forward holds once the clip has ended: clip (its last frame) or stance (it moves to the standing pose of ``task.stand_pose`` over ``ffc_blend`` s; ours: held by PD the clip's last frame falls in ~1.3 s, docs/getup.md)."""
    ffc_blend: float = 0.5
    """S over which the feed-forward moves from the clip's last frame to the stance (``ffc_hold=stance``)."""
    ffc_velocity: bool = False
    """With ``action=ffc_fbc``: the clip's joint velocities at the feed-forward's time as the PD target velocities (ours, as spacetime's experiment=laptop; false: zero, 002 §4.2)."""

    def check(self) -> None:
        """One-line ``JtError`` for each mistake (unknown curve or style, control-point count ...)."""
        from toolkit.schema import finite, require

        from jt_tasks.getup.curves import build_curves
        from jt_tasks.getup.initial import STAND_POSES, STYLES

        require(self.n_control >= 4, "task.n_control", self.n_control, "a cubic B-spline needs >= 4 control points")
        require(self.extraction in ("sample", "lstsq"), "task.extraction", self.extraction, "sample or lstsq")
        require(bool(self.curves), "task.curves", self.curves, "needs at least one curve")
        for name, spec in dict(self.authored).items():  # a curve's own duration, even where durations override it
            d = dict(spec or {}).get("duration")
            require(d is None or (finite(d) and float(d) > 0), f"task.authored.{name}.duration", d,
                    "must be > 0 s")
        for d in self.authored_durations:
            require(finite(d) and float(d) > 0, "task.authored_durations", list(self.authored_durations),
                    "durations must be > 0 s")
        try:
            build_curves(list(self.curves), dict(self.authored), list(self.authored_durations) or None,
                         self.n_control, self.extraction, self.clamped)
        except (KeyError, ValueError) as e:
            require(False, "task.curves", list(self.curves), str(e.args[0] if e.args else e))
        bad = [s for s in self.fallen_styles if s not in STYLES]
        require(not bad and bool(self.fallen_styles), "task.fallen_styles", list(self.fallen_styles),
                f"each one of {', '.join(STYLES)}")
        require(self.eval_curve in self.curves, "task.eval_curve", self.eval_curve,
                f"must be one of task.curves ({', '.join(self.curves)})")
        require(self.eval_episodes >= 1, "task.eval_episodes", self.eval_episodes, "must be >= 1")
        require(self.n_fallen >= 0, "task.n_fallen", self.n_fallen, "must be >= 0")
        require(self.stand_pose in STAND_POSES, "task.stand_pose", self.stand_pose, f"one of {', '.join(STAND_POSES)}")
        require(finite(self.rsi) and 0.0 <= self.rsi <= 1.0, "task.rsi", self.rsi, "must be in [0, 1]")
        require(finite(self.rsi_from) and 0.0 <= self.rsi_from < 1.0, "task.rsi_from", self.rsi_from,
                "must be a fraction of the clip in [0, 1)")
        require(finite(self.rsi_step) and 0.0 <= self.rsi_step <= 1.0, "task.rsi_step", self.rsi_step, "must be in [0, 1]")
        require(finite(self.rsi_success) and 0.0 < self.rsi_success <= 1.0, "task.rsi_success", self.rsi_success,
                "must be in (0, 1]")
        require(isinstance(self.rsi_episodes, int) and self.rsi_episodes >= 1, "task.rsi_episodes",
                self.rsi_episodes, "must be an integer >= 1")
        require(self.rsi > 0.0 or not (self.rsi_from or self.rsi_step), "task.rsi", self.rsi,
                "task.rsi_from / task.rsi_step shape the starts inside the clip: they need task.rsi > 0")
        for key in ("start_noise", "eval_start_noise"):
            v = getattr(self, key)
            require(finite(v) and 0.0 <= v <= 1.0, f"task.{key}", v, "must be a finite number in [0, 1] rad")
        for key in ("eval_clip_starts", "eval_every", "eval_clip_during"):
            v = getattr(self, key)
            require(isinstance(v, int) and v >= 0, f"task.{key}", v, "must be an integer >= 0")
        require(any(c in REFERENCE for c in self.curves) or not (self.eval_clip_starts or self.eval_every or self.rsi),
                "task.curves", list(self.curves), "clip starts (task.rsi, task.eval_clip_starts, task.eval_every) "
                f"need a reference curve ({', '.join(REFERENCE)})")
        for key in ("p_standing", "p_fallen"):
            v = getattr(self, key)
            require(finite(v) and 0.0 <= v <= 1.0, f"task.{key}", v, "must be in [0, 1]")
        require(self.p_standing + self.p_fallen <= 1.0, "task.p_standing+p_fallen",
                self.p_standing + self.p_fallen, "must be <= 1")
        require(not self.rsi or self.p_standing + self.p_fallen < 1.0, "task.rsi", self.rsi,
                "shapes the episodes that start from a clip, and with task.p_standing + task.p_fallen = 1 none "
                "does; set task.rsi=0 or lower one of them")
        for key in ("t_stand", "sustain", "settle_max", "time_scale", "heightmap_spacing", "success_height"):
            v = getattr(self, key)
            require(finite(v) and v > 0, f"task.{key}", v, "must be a finite number > 0")
        for key in ("head_grace", "success_window", "r_task_min", "drop_height", "drop_perturb", "ragdoll_kd",
                    "rest_speed"):
            v = getattr(self, key)
            require(finite(v) and v >= 0, f"task.{key}", v, "must be a finite number >= 0")
        if self.terrain:
            known = [f.name for f in dataclasses.fields(TerrainSpec)]
            for key in self.terrain:
                why = " (the terrain is boxes, not a heightfield, since December 2026)" if key == "cell" else ""
                require(key in known, f"task.terrain.{key}", self.terrain[key],
                        f"is not a terrain key{why}; the keys: {', '.join(known)}")
            try:
                bad = TerrainSpec.from_dict(dict(self.terrain)).check()
            except TypeError as e:
                bad = [str(e)]
            require(not bad, "task.terrain", dict(self.terrain), "; ".join(bad))
        require(self.train_regions in ("curriculum", "flat"), "task.train_regions", self.train_regions,
                "curriculum or flat")
        unknown = [r for r in self.eval_regions if r not in REGIONS]
        require(not unknown, "task.eval_regions", list(self.eval_regions), f"each one of {', '.join(REGIONS)}")
        require(bool(self.terrain) or all(r == "flat" for r in self.eval_regions), "task.eval_regions",
                list(self.eval_regions), "only flat without a terrain (task.terrain=null)")
        require(isinstance(self.eval_locations, int) and self.eval_locations >= 1, "task.eval_locations",
                self.eval_locations, "an integer >= 1 (task.eval_regions=[] skips the Table 1 evaluation)")
        require(self.drop_hz is None or (finite(self.drop_hz) and self.drop_hz >= 30.0), "task.drop_hz", self.drop_hz,
                "null or >= 30 Hz")
        require(self.ffc_hold in ("clip", "stance"), "task.ffc_hold", self.ffc_hold, "clip or stance")
        require(finite(self.ffc_blend) and self.ffc_blend > 0, "task.ffc_blend", self.ffc_blend, "must be > 0 s")
        require(isinstance(self.ffc_lead, int) and self.ffc_lead >= 0, "task.ffc_lead", self.ffc_lead,
                "control steps, an integer >= 0")
        require(self.heightmap_n >= 1, "task.heightmap_n", self.heightmap_n, "must be >= 1")
        require(0.0 < self.curve_match_deg <= 180.0, "task.curve_match_deg", self.curve_match_deg, "in (0, 180]")
        require(self.friction is None or (finite(self.friction) and self.friction >= 0), "task.friction",
                self.friction, "null or >= 0")
        require(self.filmstrip_frames >= 0 and self.filmstrip_width > 0 and self.filmstrip_height > 0,
                "task.filmstrip_frames/width/height", (self.filmstrip_frames, self.filmstrip_width,
                                                       self.filmstrip_height), "frames >= 0, sizes > 0")
