"""Feature curves of the get-up style (``003`` §4.1, §5.5, eq 1).

A curve is three cubic B-splines — target neck height ``p_h``, side angle ``p_θx``, front angle
``p_θz`` — with 9 control points each ("nine control points are sufficient", §4.1) on uniform
knots, over ``s = min((t − t0) / T, 1)`` (eq 1), ``T`` the get-up duration. jt's splines
(``toolkit.motion.splines``) clamp the end knots, so a curve starts at its first control point (the
fallen value) and ends at its last (the standing value); the interior knots are uniform.

Reference curves are extracted from the DeepMimic get-up clips ``getup_facedown`` and
``getup_faceup`` (and their left/right mirrors, ``_mirror``): the clip's features (neck height
above the clip's floor, y = 0, and the two torso angles, ``toolkit.motion.features``) sampled at 9
instants (``extraction: sample``, §4.1 "sampling them at nine equally distributed instances in
time", at the knots' Greville abscissae) or fitted by least squares (``lstsq``, ours). Authored
curves are given as control points. The episode lasts ``T + T_stand``, ``T_stand`` = 3 s (§5.6).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import os
from typing import Any, Optional

import numpy as np

from toolkit.motion.splines import N_CONTROL, BSplineCurve, normalised_time

FEATURES = ("h", "theta_x", "theta_z")  #: the three curves of a style, in ``c`` order (§3.4)
CLIPS = ("getup_facedown", "getup_faceup")  #: DeepMimic get-up clips of pybullet_data
#: the reference curve names: the clip without ``getup_``, ``_mirror`` for the mirrored clip
REFERENCE = tuple(f"{c[len('getup_'):]}{m}" for c in CLIPS for m in ("", "_mirror"))


@dataclasses.dataclass
class FeatureCurve:
    """One get-up style: three curves over ``s`` in [0, 1], a duration and where it comes from.

    Attributes:
        name: the curve's name (``facedown``, ``faceup_mirror``, an authored name ...).
        control: control points ``(n_control, 3)``, columns ``FEATURES`` (m, rad, rad).
        duration: ``T`` (s), the get-up's duration.
        clip: the clip whose first pose starts the curve (``getup_facedown`` ...), or "" (authored).
        mirrored: the clip is mirrored left/right.
        clamped: clamped end knots (jt's default) or the unclamped cardinal spline.
    """

    name: str
    control: np.ndarray
    duration: float
    clip: str = ""
    mirrored: bool = False
    clamped: bool = True

    def __post_init__(self) -> None:
        self.control = np.asarray(self.control, dtype=np.float64).reshape(-1, len(FEATURES))
        self._spline = BSplineCurve(self.control, self.clamped)

    def s(self, t: Any) -> np.ndarray:
        """``s = min((t − t0) / T, 1)`` (eq 1) at episode times ``t`` (t0 = 0; also ≥ 0)."""
        return normalised_time(t, 0.0, self.duration)

    def __call__(self, t: Any) -> np.ndarray:
        """Targets ``(p_h, p_θx, p_θz)`` ``(..., 3)`` at episode times ``t`` ``(...)``."""
        return self._spline(self.s(t))

    def at_s(self, s: Any) -> np.ndarray:
        """Targets at curve parameters ``s`` (clamped to [0, 1])."""
        return self._spline(np.asarray(s, dtype=np.float64))

    @property
    def start(self) -> np.ndarray:
        """``p(0)`` ``(3,)``: the fallen features the curve starts from."""
        return self.at_s(0.0)

    @property
    def end(self) -> np.ndarray:
        """``p(1)`` ``(3,)``: the standing features."""
        return self.at_s(1.0)

    def scaled(self, time_scale: float) -> "FeatureCurve":
        """The same curve lasting ``time_scale · T`` (§4.3: "the duration of the motion can be adjusted
        simply by changing the duration T")."""
        return dataclasses.replace(self, duration=self.duration * float(time_scale))

    def to_dict(self) -> dict:
        """Plain, picklable form (env specs)."""
        return {"name": self.name, "control": self.control.tolist(), "duration": float(self.duration),
                "clip": self.clip, "mirrored": bool(self.mirrored), "clamped": bool(self.clamped)}

    @classmethod
    def from_dict(cls, d: dict) -> "FeatureCurve":
        return cls(str(d["name"]), np.asarray(d["control"], float), float(d["duration"]), str(d.get("clip", "")),
                   bool(d.get("mirrored", False)), bool(d.get("clamped", True)))


def clip_path(clip: str) -> str:
    """The ``humanoid3d_<clip>.txt`` file of pybullet_data."""
    from toolkit.motion.skeletons import motions_dir

    return os.path.join(motions_dir(), f"humanoid3d_{clip}.txt")


@functools.lru_cache(maxsize=8)
def load_getup_clip(clip: str, mirrored: bool = False) -> Any:
    """A get-up clip (``toolkit.motion.Clip``), mirrored if asked (memoised per process)."""
    from toolkit.motion import load_clip

    c = load_clip(clip_path(clip))
    return c.mirror() if mirrored else c


@functools.lru_cache(maxsize=8)
def clip_feature_track(clip: str, mirrored: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """``(times (n,), features (n, 3))`` of a clip's frames: θx, θz and the neck height above the
    ground the frame rests on — its own lowest point less ``ground.CLEARANCE``, the frame a start
    pose is put in (``ground.lift_to_ground``). The clips' mocap ground is 3-5 cm off and not
    level (the faceup clip ends 2.7 cm lower than it starts): heights above y = 0 put every
    simulated height 3.6-7.5 cm above its curve (issue 29)."""
    from jt_tasks.getup.ground import CLEARANCE, lowest_point
    from toolkit.motion.features import clip_features

    c = load_getup_clip(clip, mirrored)
    ground = np.array([lowest_point(np.concatenate([c.root_pos[i], c.root_rot[i], c.joints[i]]))
                       for i in range(c.n_frames)]) - CLEARANCE
    _, cond, _ = clip_features(c, ground_height=ground)
    return np.asarray(c.times, float), np.asarray(cond, float)


def reference_curve(name: str, n_control: int = N_CONTROL, extraction: str = "sample",
                    clamped: bool = True) -> FeatureCurve:
    """The reference curve ``name`` (``REFERENCE``) extracted from its clip."""
    mirrored = name.endswith("_mirror")
    clip = "getup_" + (name[: -len("_mirror")] if mirrored else name)
    if clip not in CLIPS:
        raise KeyError(f"no reference curve {name!r}; known: {', '.join(REFERENCE)}")
    times, feats = clip_feature_track(clip, mirrored)
    T = float(times[-1] - times[0])
    spline = BSplineCurve.from_samples((times - times[0]) / T, feats, n_control, clamped, extraction)
    return FeatureCurve(name, spline.control, T, clip, mirrored, clamped)


def replay_score(curve: FeatureCurve) -> dict[str, float]:
    """How well the curve fits its own clip: mean and minimum of r_h · r_θ (eqs 5-6) over the
    clip's frames (a check of the extraction; notes: 0.73-0.86 mean)."""
    if not curve.clip:
        return {}
    times, feats = clip_feature_track(curve.clip, curve.mirrored)
    target = curve(times - times[0])
    r = np.exp(-1.7 * np.abs(feats[:, 0] - target[:, 0])
               - 1.5 * (np.abs(feats[:, 1] - target[:, 1]) + np.abs(feats[:, 2] - target[:, 2])))
    return {"mean": float(r.mean()), "min": float(r.min())}


def build_curves(names: list[str], authored: dict, durations: Optional[list], n_control: int = N_CONTROL,
                 extraction: str = "sample", clamped: bool = True, time_scale: float = 1.0) -> list[FeatureCurve]:
    """The training set of curves: each named one (a reference curve, else an authored one from
    ``authored[name] = {h: [...], theta_x: [...], theta_z: [...], duration: T}``, else one of the
    built-in authored styles ``styles.STYLES``, which ``authored`` may override), authored curves
    once per entry of ``durations`` when given (§5.5: 2.5, 5.1, 7.6 s), all durations × ``time_scale``.

    Raises:
        KeyError / ValueError: an unknown name, a wrong control-point count (``Config.check`` turns
        them into one-line ``JtError`` s at composition).
    """
    from jt_tasks.getup.styles import authored_styles

    authored = {**authored_styles(), **dict(authored or {})}
    out = []
    for name in names:
        if name in REFERENCE:
            out.append(reference_curve(name, n_control, extraction, clamped).scaled(time_scale))
            continue
        if name not in authored:
            raise KeyError(f"unknown curve or style {name!r}: reference curves are {', '.join(REFERENCE)}; "
                           f"authored styles: {', '.join(sorted(authored))}")
        spec = dict(authored[name])
        cols = []
        for f in FEATURES:
            pts = list(spec.get(f) or [])
            if len(pts) != n_control:
                raise ValueError(f"curve {name!r}: {f} has {len(pts)} control points, needs {n_control} (003 §4.1)")
            cols.append([float(v) for v in pts])
        ctrl = np.array(cols).T
        base = float(spec.get("duration", 0.0) or 0.0)
        Ts = [float(d) for d in durations] if durations else [base]
        for T in Ts:
            if not (T > 0 and math.isfinite(T)):
                raise ValueError(f"curve {name!r}: duration must be > 0 s, got {T}")
            tag = name if len(Ts) == 1 else f"{name}@{T:g}s"
            out.append(FeatureCurve(tag, ctrl, T * float(time_scale), "", False, clamped))
    return out
