"""Spacetime bounds (``002`` §3.2 eq 2, §5.1): the difference vector and its per-channel widths.

The state of a character is out of bounds when any channel of the difference vector between it
and the reference at the same time exceeds that channel's width σ. The humanoid's 22 channels,
in the authors' order (research notes):

* 0–2 ``com_x``, ``com_y``, ``com_z``: absolute CoM difference per world axis (m);
* 3 ``root``: shortest-arc angle between the world root quaternions (rad);
* 4–17 each link's joint (``chest`` ... ``left_wrist``, PyBullet link order): the angle of the
  local rotation difference (quaternion angle for spherical joints, ``|Δθ|`` for the knees and
  elbows; the wrists are fixed joints, their channel is always 0) (rad);
* 18–21 ``ee_right_ankle``, ``ee_right_wrist``, ``ee_left_ankle``, ``ee_left_wrist`` (the authors'
  bound files' order, so a width table copied from them lands on its channels): distance
  between the end effectors (joint origins) of the two characters, each relative to its own
  ground-projected root in its own heading frame (m).

Widths (002 §5.1): CoM 0.2 m, orientations (root and joints) 0.7 rad, end effectors 0.5 m; a
width of ``inf`` / ``None`` switches a channel off. A phase table (the authors' format, research
notes) gives K rows of widths evenly over phase [0, 1], linearly interpolated at the clip's phase
(``width_table``, ``widths_at``); every table the authors ship is constant.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Mapping, Optional

import numpy as np

from jt_tasks.spacetime.reference import END_EFFECTORS

COM = ("com_x", "com_y", "com_z")
ROOT = ("root",)
END_EFFECTOR_NAMES = tuple(f"ee_{name}" for name in END_EFFECTORS)
GROUPS = ("com", "orientation", "end_effector")


def joint_channels(skeleton: Any) -> tuple[str, ...]:
    """The joint channels: every link of the skeleton but its root link, in link order."""
    return tuple(skeleton.links[1:])


def channel_names(skeleton: Any) -> tuple[str, ...]:
    """All 22 channel names, in order."""
    return COM + ROOT + joint_channels(skeleton) + END_EFFECTOR_NAMES


@dataclasses.dataclass(frozen=True)
class BodyState:
    """What the bounds compare of one character.

    Attributes:
        q: pose ``(n_q,)`` (root position, root quaternion x, y, z, w, joints in the quaternion layout).
        com: whole-body CoM ``(3,)`` (world).
        ee: end effectors ``(4, 3)``: joint origins relative to the ground-projected root, heading frame.
    """

    q: np.ndarray
    com: np.ndarray
    ee: np.ndarray


def _joint_columns(skeleton: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """For ``difference``: the joint-channel positions and quaternion columns ``(n, 4)`` of the
    spherical joints, the channel positions and columns of the revolute ones (fixed joints, the
    wrists, are neither and stay 0); cached on the skeleton."""
    cached = skeleton.__dict__.get("_bound_columns")
    if cached is None:
        by_name = {j.name: (j, s) for j, s in zip(skeleton.joints, skeleton.q_slices.values())}
        sph_at, sph_cols, rev_at, rev_cols = [], [], [], []
        for k, name in enumerate(joint_channels(skeleton)):
            if name not in by_name:
                continue
            j, s = by_name[name]
            if j.kind == "spherical":
                sph_at.append(k)
                sph_cols.append(list(range(s.start, s.stop)))
            else:
                rev_at.append(k)
                rev_cols.append(s.start)
        cached = (np.array(sph_at, dtype=int), np.array(sph_cols, dtype=int).reshape(-1, 4),
                  np.array(rev_at, dtype=int), np.array(rev_cols, dtype=int))
        object.__setattr__(skeleton, "_bound_columns", cached)
    return cached


def _angle_columns(skeleton: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For ``difference``: the pose columns ``(1 + n_spherical, 4)`` of the root and every
    spherical joint's quaternion, their channels ``(1 + n_spherical,)`` (the root's is 3), and the
    revolute joints' pose columns; cached on the skeleton."""
    cached = skeleton.__dict__.get("_bound_angle_columns")
    if cached is None:
        sph_at, sph_cols, rev_at, rev_cols = _joint_columns(skeleton)
        cols = np.vstack([np.arange(3, 7)[None, :], np.asarray(sph_cols, dtype=int).reshape(-1, 4) + 7])
        at = np.concatenate([[3], 4 + np.asarray(sph_at, dtype=int)]).astype(int)
        cached = (cols, at, 4 + np.asarray(rev_at, dtype=int), 7 + np.asarray(rev_cols, dtype=int))
        object.__setattr__(skeleton, "_bound_angle_columns", cached)
    return cached


def difference(skeleton: Any, a: BodyState, b: BodyState) -> np.ndarray:
    """The 22-channel difference vector ``(n_channels,)`` between two states (all >= 0).

    The root and every spherical joint in one pass: the angle of ``conj(qa) qb``,
    ``2 atan2(|xyz|, |w|)`` (``quat_angle``), row-wise.
    """
    cols, at, rev_at, rev_cols = _angle_columns(skeleton)
    qa, qb = np.asarray(a.q, dtype=float), np.asarray(b.q, dtype=float)
    out = np.zeros(4 + len(joint_channels(skeleton)) + len(END_EFFECTOR_NAMES))
    out[:3] = np.abs(np.asarray(a.com, dtype=float) - np.asarray(b.com, dtype=float)).reshape(-1)
    ax, ay, az, aw = qa[cols].T
    bx, by, bz, bw = qb[cols].T
    # conj(a) * b (quat_relative), the Hamilton product's sums in its order
    rx = aw * bx - ax * bw - ay * bz + az * by
    ry = aw * by + ax * bz - ay * bw - az * bx
    rz = aw * bz - ax * by + ay * bx - az * bw
    rw = aw * bw + ax * bx + ay * by + az * bz
    out[at] = 2.0 * np.arctan2(np.sqrt(rx * rx + ry * ry + rz * rz), np.abs(rw))
    out[rev_at] = np.abs(qa[rev_cols] - qb[rev_cols])
    e = np.asarray(a.ee, dtype=float) - np.asarray(b.ee, dtype=float)
    out[-len(END_EFFECTOR_NAMES):] = np.sqrt(np.einsum("ij,ij->i", e, e))
    return out


def _off(value: Any) -> bool:
    return value is None or (isinstance(value, (int, float)) and not isinstance(value, bool) and math.isinf(value) and value > 0)


def _width(where: str, v: Any) -> float:
    """One width (``inf`` for off); a non-number or a width <= 0 is one ``JtError`` line."""
    from toolkit.errors import JtError

    if _off(v):
        return math.inf
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise JtError(f"{where}={v!r}: a bound width must be a number > 0 (null or .inf: off)") from None
    if not x > 0 or math.isnan(x):
        raise JtError(f"{where}={v!r}: a bound width must be > 0 (null or .inf switches a channel off)")
    return x


def _override(skeleton: Any, w: np.ndarray, per_channel: Mapping[str, Any], where: str) -> np.ndarray:
    """``w`` ``(n_channels,)`` with ``{channel or group name: width}`` applied (in place)."""
    from toolkit.errors import JtError

    names = channel_names(skeleton)
    n_joint = len(joint_channels(skeleton))
    groups = {"com": range(0, 3), "orientation": range(3, 4 + n_joint), "end_effector": range(4 + n_joint, len(names))}
    for key, v in dict(per_channel or {}).items():
        key = str(key)
        if key in groups:
            w[list(groups[key])] = _width(f"{where}.{key}", v)
        elif key in names:
            w[names.index(key)] = _width(f"{where}.{key}", v)
        else:
            raise JtError(f"{where}.{key}: unknown bound channel; one of: {', '.join(GROUPS + names)}")
    return w


def widths(skeleton: Any, com: Any = 0.2, orientation: Any = 0.7, end_effector: Any = 0.5,
           per_channel: Optional[Mapping[str, Any]] = None) -> np.ndarray:
    """Per-channel widths ``(n_channels,)`` (``inf``: off) from the group widths and overrides.

    Args:
        com: m, the three CoM channels (a number, or ``[x, y, z]``).
        orientation: rad, the root and joint channels.
        end_effector: m, the four end-effector channels.
        per_channel: ``{channel or group name: width}`` overriding the above; ``None``/``inf``: off.

    Raises:
        JtError: a width <= 0 or not a number, an unknown channel name (one line).
    """
    from toolkit.errors import JtError

    n_joint = len(joint_channels(skeleton))
    com_w = [_width("task.com_width", c) for c in (com if isinstance(com, (list, tuple)) else [com] * 3)]
    if len(com_w) != 3:
        raise JtError(f"task.com_width={com!r}: one width or three (x, y, z)")
    w = np.array(com_w + [_width("task.orientation_width", orientation)] * (1 + n_joint)
                 + [_width("task.end_effector_width", end_effector)] * 4)
    return _override(skeleton, w, per_channel or {}, "task.widths")


def width_table(skeleton: Any, base: np.ndarray, rows: Any) -> np.ndarray:
    """A phase table ``(K, n_channels)`` from ``rows``: each row ``{channel or group: width}``
    overriding the constant widths ``base`` ``(n_channels,)`` at that row's phase (``None``/``inf``:
    off), or a full list of ``n_channels`` widths. Row k lies at phase ``k / (K - 1)`` (one row:
    constant). An empty ``rows`` gives a ``(0, n_channels)`` table (no table: ``base`` throughout).

    Raises:
        JtError: a row that is neither, a width <= 0, an unknown channel (one line).
    """
    from toolkit.errors import JtError

    names = channel_names(skeleton)
    out = []
    for k, row in enumerate(list(rows or [])):
        where = f"task.width_table[{k}]"
        if isinstance(row, Mapping):
            w = _override(skeleton, np.asarray(base, dtype=float).copy(), row, where)
        elif isinstance(row, (list, tuple)) and len(row) == len(names):
            w = np.array([_width(f"{where}[{i}]", v) for i, v in enumerate(row)])
        else:
            raise JtError(f"{where}={row!r}: a row is {{channel or group: width}} or a list of "
                          f"{len(names)} widths ({', '.join(names)})")
        out.append(w)
    return np.array(out, dtype=float).reshape(-1, len(names))


def widths_at(table: np.ndarray, phase: float) -> np.ndarray:
    """Widths ``(n_channels,)`` of a phase table ``(K, n_channels)`` at ``phase`` (taken mod 1):
    linear interpolation between the two rows around it; an ``inf`` (off) row keeps the channel
    off between it and its neighbours (a row's own phase gives that row exactly)."""
    k = table.shape[0]
    if k == 1:
        return table[0].copy()
    x = (float(phase) % 1.0) * (k - 1)
    i = min(int(x), k - 2)
    u = x - i
    if u == 0.0:
        return table[i].copy()
    return (1.0 - u) * table[i] + u * table[i + 1]


def violations(d: np.ndarray, w: np.ndarray, names: tuple[str, ...]) -> list[str]:
    """Names of the channels with ``d > w``."""
    return [names[i] for i in np.flatnonzero(np.asarray(d) > np.asarray(w))]
