"""The reference run of the run-up task: the DeepMimic run clip, its take-off schedule and kinematics.

``RunReference`` wraps ``humanoid3d_run.txt`` (``000`` §6.1.1 used the authors' own sprints; we use
the DeepMimic clip, as the jump tasks do) and answers what the run-up environment asks of it:

* the take-off instant: the middle of a support phase of the take-off foot, found exactly as the
  jump tasks find it (``jt_tasks.takeoff.state.support_phase_time``), repeating once per cycle;
* the reference state ``(q, qd)`` at any clip time (``jt_tasks.takeoff.state.reference_state``: slerp pose and
  central-difference velocities, the root shifted by the clip's cycle offset on every loop);
* forward kinematics of a state (link centres of mass, whole-body CoM) by a kinematic copy of
  the humanoid (``toolkit.motion.kinematics.kinematic_body``, never stepped);
* ``at(j)``: all of the above at clip time ``j / sim_hz``, memoised per process (the environment
  keeps its clip times on the simulation grid, so an episode's reference is computed once and
  shared by every environment of a rollout worker).

The clip's feet dip a few cm into the ground (its own world); the whole clip is lifted by
``ground_offset`` so that the take-off foot is ``foot_clearance`` above the ground at the
take-off instant, as ``JumpEnv`` places its take-off state.
"""

from __future__ import annotations

import dataclasses
import math
import os
from typing import Optional

import numpy as np

from jt_tasks.takeoff.state import FOOT_LINKS, heading_quat, reference_state, support_phase_time
from toolkit.motion import rotations as rot

#: hands and feet by link name: the end effectors of Peng et al. 2018 §6 (the env resolves them
#: once, ``Simulator.link_index``)
END_EFFECTORS = (FOOT_LINKS["right"], FOOT_LINKS["left"], "right_wrist", "left_wrist")
#: ``RunReference.at`` memo: {(clip, foot, contact_tol, clearance, sim_hz): {j: RefSample}}
_MEMO: dict[tuple, dict[int, "RefSample"]] = {}
_MEMO_MAX = 20000  # samples per reference (about 33 s of clip time at 600 Hz)


@dataclasses.dataclass(frozen=True)
class RefSample:
    """The reference at one clip time.

    Attributes:
        q: positions ``(n_q,)``; qd: velocities ``(n_dof,)`` (``toolkit.dynamics`` layout).
        links: link centres of mass ``(n_links + 1, 3)``, base first; com: CoM ``(3,)`` (world).
    """

    q: np.ndarray
    qd: np.ndarray
    links: np.ndarray
    com: np.ndarray


class RunReference:
    """The looped reference run, its take-off instants and a kinematic copy of the character.

    Args:
        clip_name: a DeepMimic humanoid clip (``humanoid3d_<name>.txt``) or a path.
        foot: take-off foot, ``right`` or ``left``.
        contact_tol: a foot within this height (m) of its lowest is on the ground (``jt_tasks.takeoff.state``).
        foot_clearance: height (m) of the take-off foot's lowest point at the take-off instant.
        sim_hz: rate of the time grid of ``at``.
    """

    def __init__(self, clip_name: str = "run", foot: str = "right", contact_tol: float = 0.06,
                 foot_clearance: float = 0.002, sim_hz: float = 600.0) -> None:
        from toolkit.motion import load_clip
        from toolkit.motion.kinematics import kinematic_body
        from toolkit.motion.skeletons import motions_dir

        path = clip_name if os.path.sep in clip_name else os.path.join(motions_dir(), f"humanoid3d_{clip_name}.txt")
        self.clip = load_clip(path)
        if not self.clip.loop:
            from toolkit.errors import JtError

            raise JtError(f"runup: the reference clip {path} does not loop; a run-up needs a looping run")
        self.skeleton = self.clip.skeleton
        self.foot = foot
        self.period = float(self.clip.duration)
        self.t_mid, _ = support_phase_time(self.clip, foot, contact_tol)
        self.body = kinematic_body(self.skeleton)
        self.masses = self.body.masses
        self.ground_offset = 0.0
        q, _ = self.state(self.t_mid)
        self.ground_offset = float(foot_clearance - self.lowest_point(q, FOOT_LINKS[foot]))
        self.sim_hz = float(sim_hz)
        key = (os.path.abspath(path), foot, float(contact_tol), float(foot_clearance), self.sim_hz)
        self._memo = _MEMO.setdefault(key, {})

    def at(self, j: int) -> RefSample:
        """The reference at clip time ``j / sim_hz`` (memoised)."""
        j = int(j)
        hit = self._memo.get(j)
        if hit is None:
            q, qd = self.state(j / self.sim_hz)
            links, com = self.kinematics(q)
            hit = RefSample(q, qd, links, com)
            if len(self._memo) < _MEMO_MAX:
                self._memo[j] = hit
        return hit

    # ------------------------------------------------------------------ schedule
    def takeoff_time(self, t0: float, n_strides: int, min_gap: float = 0.0) -> float:
        """Clip time of the ``n_strides``-th take-off-foot mid-support later than ``t0 + min_gap``.

        The first one lies in ``(t0 + min_gap, t0 + min_gap + period]``, each later one a period on.
        """
        k = math.floor((t0 + min_gap - self.t_mid) / self.period) + 1
        return self.t_mid + (k + n_strides - 1) * self.period

    def phase(self, t: float) -> float:
        """Clip phase in ``[0, 1)`` of clip time ``t``."""
        return float((t / self.period) % 1.0)

    # ------------------------------------------------------------------ states
    def state(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Reference ``(q (n_q,), qd (n_dof,))`` at clip time ``t`` (``toolkit.dynamics`` layout)."""
        p, r, j, v, w, jv = reference_state(self.clip, float(t))
        p = p + np.array([0.0, self.ground_offset, 0.0])
        return np.concatenate([p, r, j]), np.concatenate([v, w, jv])

    def lowest_point(self, q: np.ndarray, link: Optional[int | str] = None) -> float:
        """Lowest height of a link's bounding box (or of the whole body) in pose ``q``.

        Args:
            q: the pose ``(n_q,)``.
            link: a link name, else its index in the skeleton's order (the kinematic body's
                PyBullet indices); None: every link.
        """
        if isinstance(link, str):
            link = self.skeleton.link_index(link)
        return self.body.lowest_point(q, link)

    def kinematics(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Link centres of mass ``(n_links + 1, 3)`` (base first) and the CoM ``(3,)`` of pose ``q``."""
        return self.body.links_and_com(q)

    def close(self) -> None:
        """Release the kinematic copy (idempotent)."""
        self.body.close()


def facing_frame(q: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``points (..., 3)`` relative to the root of ``q``, in its facing frame (``jt_tasks.takeoff.state``)."""
    inv = rot.quat_conjugate(heading_quat(np.asarray(q[3:7])))
    return rot.quat_rotate(inv, np.asarray(points) - np.asarray(q[:3]))

