"""``action=ffc_fbc``: feed-forward reference pose plus the policy's feedback correction (``002`` §4.2).

``002`` Fig. 4: the feed-forward controller (FFC) "stores the joint angles from the reference and
linearly interpolates them at run time according to the current phase index φ to generate q̂";
the feedback controller (the policy network) outputs corrections Δq; the PD target is
``q = q̂ + Δq``, "all angles ... parameterized in exponential maps". The reference's exp maps are
unwrapped along the clip (each frame takes the representative ``v + 2πn v̂`` nearest the previous
frame's) so that linear interpolation never crosses the ``|v| = π`` seam.

The phase ``φ ∈ [0, 1]`` comes from ``obs["phase"]`` / ``obs.phase`` / a bare number passed as
``obs``, or from ``set_phase``; a looping clip wraps φ, a non-looping one clamps it. ``reset(state)``
sets φ to ``state`` (a number) or 0. There is no naturalness term (``penalty() == 1``).

``output_scale: range`` (default, the authors' code): the policy network's output is multiplied
per DoF by the joint's range in the authors' humanoid character file (``a_std = LimHigh −
LimLow``, 2–4.14 rad, ``JOINT_RANGES``) before it is the mean correction; the exploration noise
stays in radians (σ = 0.1). The environment exposes it as ``policy_output_scale`` for PPO's
networks. ``none``: the network's output is the correction.
"""

from __future__ import annotations

import bisect
import dataclasses
import math
import os
from numbers import Real
from typing import Any, ClassVar

import numpy as np

from jt_actions.base import DofActionSpace, FilterCheck, obs_value
from toolkit.errors import JtError


def resolve_clip(name: str) -> str:
    """Path of a clip given as a path or a name in ``pybullet_data``'s motions (``walk``,
    ``humanoid3d_walk``, ``laikago_walk``)."""
    from toolkit.motion.skeletons import motions_dir

    d = motions_dir()
    for cand in (name, f"{name}.txt", os.path.join(d, name), os.path.join(d, f"{name}.txt"),
                 os.path.join(d, f"humanoid3d_{name}.txt")):  # fmt: skip
        if os.path.isfile(cand):
            return cand
    known = sorted(f[:-4].replace("humanoid3d_", "") for f in os.listdir(d) if f.endswith(".txt"))
    raise JtError(f"action=ffc_fbc: no clip '{name}'; give a path or one of: {', '.join(known)}")


#: rad, per joint DoF: LimHigh − LimLow of the authors' humanoid3d character file (the actor's
#: a_std; 002 authors' code, DeepMimic's humanoid), x, y, z of each exp map, the revolute angle
JOINT_RANGES = {
    "chest": (2.4, 2.4, 2.4), "neck": (2.0, 2.0, 2.0),
    "right_hip": (2.4, 2.0, 4.14), "right_knee": (3.14,), "right_ankle": (2.0, 2.0, 3.14),
    "right_shoulder": (3.64, 3.0, 3.84), "right_elbow": (3.14,),
    "left_hip": (2.4, 2.0, 4.14), "left_knee": (3.14,), "left_ankle": (2.0, 2.0, 3.14),
    "left_shoulder": (3.64, 3.0, 3.84), "left_elbow": (3.14,),
}


def unwrap_expmaps(v: np.ndarray) -> np.ndarray:
    """Exp maps ``(n, 3)`` made continuous along the first axis (same rotations)."""
    out = np.array(v, dtype=np.float64, copy=True)
    for k in range(1, len(out)):
        theta = np.linalg.norm(out[k])
        if theta < 1e-9:
            continue
        axis = out[k] / theta
        cands = out[k][None, :] + 2.0 * np.pi * np.arange(-2, 3)[:, None] * axis[None, :]
        out[k] = cands[np.argmin(np.linalg.norm(cands - out[k - 1], axis=1))]
    return out


class FFCFBCActionSpace(DofActionSpace):
    """Target = reference pose at the phase (feed-forward) + the policy's correction (002 §4.2)."""

    needs: ClassVar[frozenset[str]] = frozenset({"phase"})  #: the reference clip's phase each control step

    @dataclasses.dataclass
    class Config(FilterCheck):
        name: str = "ffc_fbc"
        clip: str = "walk"
        """Reference clip: a pybullet_data motion name (walk, run, backflip, ...) or a path."""
        correction_bound: float = 1.0
        """Ours: |dq| bound per DoF (rad); 002 gives none."""
        clip_to_limits: bool = True
        """Targets within the joint limits."""
        beta: float = 1.0
        """Action filter y_t = beta a_t + (1 - beta) y_{t-1} (003 §3.4's, an option of every action
        space); 1: no filter (002 filters nothing)."""
        output_scale: str = "range"
        """range: the policy's output times each DoF's joint range (authors' code, a_std); none: 1."""

        def check(self) -> None:
            super().check()
            if self.output_scale not in ("range", "none"):
                raise JtError(f"action.output_scale={self.output_scale!r}: range (the authors' joint ranges) or none")
            from toolkit.motion.clips import ClipError, load_clip

            try:  # read at composition: a missing or broken clip is one line before a run opens
                load_clip(resolve_clip(self.clip))
            except ClipError as e:
                raise JtError(f"action.clip={self.clip}: {e}") from None

    def __init__(self, cfg: Any = None, character: Any = None) -> None:
        super().__init__(cfg, character)
        from toolkit.motion.clips import load_clip

        self._tracks: dict[int, tuple] = {}  # id(clip) -> (clip, times, time list, dofs): use_clip's memo
        self._phase = 0.0
        self.use_clip(load_clip(resolve_clip(self.params.clip)), name=self.params.clip)

    def use_clip(self, clip: Any, name: str = "") -> None:
        """Track ``clip`` (a ``toolkit.motion.Clip`` of the same skeleton) from now on: a task whose
        episodes follow different clips (``task=getup``: each curve's clip, mirrored or not) sets
        the episode's clip at its start. The unwrapped dof track of each clip is kept."""
        if id(clip) not in self._tracks:
            if clip.skeleton.name != self.skeleton.name:
                raise JtError(f"action=ffc_fbc: clip '{name or clip}' is for the {clip.skeleton.name}, "
                              f"the character is the {self.skeleton.name}")  # fmt: skip
            dofs = self.skeleton.joints_to_dofs(clip.joints)
            for j, s in zip(self.skeleton.joints, self.skeleton.dof_slices.values()):
                if j.kind == "spherical":
                    dofs[:, s] = unwrap_expmaps(dofs[:, s])
            times = np.asarray(clip.times, dtype=np.float64)
            self._tracks[id(clip)] = (clip, times, [float(x) for x in times], dofs)
        self.clip, self._times, self._time_list, self._dofs = self._tracks[id(clip)]

    @property
    def dim(self) -> int:
        return self.n_dof

    def output_scale(self) -> np.ndarray | None:
        """``(n_dof,)`` factors on the policy's output (``JOINT_RANGES``), or None (``none``)."""
        if self.params.output_scale == "none":
            return None
        missing = [j.name for j in self.skeleton.joints if j.kind != "fixed" and j.name not in JOINT_RANGES]
        if missing:
            raise JtError(f"action.output_scale=range: no authors' range for joint(s) {', '.join(missing)} "
                          f"of the {self.skeleton.name}; use action.output_scale=none")
        out = np.ones(self.n_dof)
        for j, s in zip(self.skeleton.joints, self.skeleton.dof_slices.values()):
            if j.name in JOINT_RANGES:
                out[s] = JOINT_RANGES[j.name]
        return out

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        high = np.full(self.n_dof, float(self.params.correction_bound))
        return -high, high

    # ---- phase ---------------------------------------------------------------------------------
    def set_phase(self, phase: float) -> None:
        """Current phase φ of the reference (wrapped for a looping clip, else clamped to [0, 1])."""
        phi = float(phase)
        if not math.isfinite(phi):
            raise ValueError(f"phase must be finite, got {phase}")
        if self.clip.loop and phi != 1.0:
            phi = phi % 1.0
        self._phase = min(max(phi, 0.0), 1.0)

    @property
    def phase(self) -> float:
        return self._phase

    def reference(self, phase: float | None = None) -> np.ndarray:
        """The FFC output q̂ ``(n_dof,)``: the clip's dofs linearly interpolated at ``phase``."""
        if phase is not None:
            self.set_phase(phase)
        times = self._time_list
        t = self._phase * times[-1]
        i = min(max(bisect.bisect_right(times, t) - 1, 0), len(times) - 2)  # np.searchsorted's
        w = min(max((t - times[i]) / (times[i + 1] - times[i]), 0.0), 1.0)
        return (1.0 - w) * self._dofs[i] + w * self._dofs[i + 1]

    # ---- control -------------------------------------------------------------------------------
    def targets(self, action: np.ndarray, obs: Any = None) -> np.ndarray:
        phase = obs if isinstance(obs, Real) else obs_value(obs, "phase")
        if phase is not None:
            self.set_phase(float(phase))
        return self.finish(self.reference() + self.filter(action))

    def reset(self, state: Any = None) -> None:
        """New episode: φ = ``state`` (a number) or 0; the filter starts from zero."""
        self.set_phase(float(state) if state is not None else 0.0)
        self.reset_filter(None)
