"""Joint limits of a character in the dof (PD-target) layout, and making targets respect them.

The dof layout (``Skeleton.dof_slices``) holds an exponential map per spherical joint and an angle
per revolute joint. Limits:

* revolute joints: the URDF's ``<limit lower upper>`` (humanoid knees ``[-3.14, 0]``, elbows
  ``[0, 3.14]``), read once from the URDF file as PyBullet reads it (a ``continuous`` joint, or
  ``lower >= upper``, has none);
* spherical joints: each exp-map component in ``[-pi, pi]``, DeepMimic's convention for spherical
  joints (the URDF gives none). ``limit_targets`` maps every spherical target to its canonical exp
  map (``|v| <= pi``, the same rotation), which satisfies this, and clips revolute angles.

The humanoid's mocap knees reach +0.17 rad (slight hyper-extension) and so leave the URDF range:
clipping them to 0 is what a PD target within the joint's range has to be.
"""

from __future__ import annotations

import functools

import numpy as np

from toolkit.motion import rotations as rot
from toolkit.motion.skeletons import SKELETONS, SPHERICAL, Skeleton


def urdf_joint_limits(path: str) -> dict[str, tuple[float, float]]:
    """``(lower, upper)`` of every limited revolute or prismatic joint of a URDF, by child link name.

    Args:
        path: the URDF file (trailing NUL bytes, as in ``pybullet_data``'s humanoid, are ignored).

    Returns:
        Child link name -> ``(lower, upper)`` for joints whose ``<limit>`` has ``lower < upper``
        (``continuous`` joints and ``lower >= upper`` mean no limit, as in PyBullet).
    """
    import xml.etree.ElementTree as ET

    with open(path, "rb") as f:
        root = ET.fromstring(f.read().replace(b"\x00", b""))
    out = {}
    for joint in root.iter("joint"):
        lim, child = joint.find("limit"), joint.find("child")
        if joint.get("type") not in ("revolute", "prismatic") or lim is None or child is None:
            continue
        lo, hi = float(lim.get("lower", 0.0)), float(lim.get("upper", 0.0))
        if lo < hi:
            out[str(child.get("link"))] = (lo, hi)
    return out


@functools.lru_cache(maxsize=None)
def _limits(skeleton_name: str) -> tuple[np.ndarray, np.ndarray]:
    sk = SKELETONS[skeleton_name]
    low, high = np.full(sk.n_dof, -np.pi), np.full(sk.n_dof, np.pi)
    urdf = urdf_joint_limits(sk.urdf_path)
    for j, s in zip(sk.joints, sk.dof_slices.values()):
        lim = urdf.get(sk.links[j.bullet_index]) if j.kind != SPHERICAL else None
        if lim is not None:  # joint j moves link j (URDF_MAINTAIN_LINK_ORDER)
            low[s], high[s] = lim
    low.setflags(write=False)
    high.setflags(write=False)
    return low, high


@functools.lru_cache(maxsize=None)
def _spherical_columns(skeleton_name: str) -> np.ndarray:
    """Dof columns of each spherical joint's exp map ``(n_spherical, 3)``."""
    sk = SKELETONS[skeleton_name]
    cols = [np.arange(s.start, s.stop) for j, s in zip(sk.joints, sk.dof_slices.values()) if j.kind == SPHERICAL]
    return np.stack(cols) if cols else np.zeros((0, 3), dtype=int)


def joint_limits(skeleton: Skeleton) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper PD-target limits ``(n_dof,)`` in the dof layout (read-only arrays)."""
    return _limits(skeleton.name)


def canonical_expmaps(skeleton: Skeleton, dofs: np.ndarray) -> np.ndarray:
    """Dofs ``(..., n_dof)`` with every spherical joint's exp map replaced by the canonical one
    (``|v| <= pi``) of the same rotation; revolute angles unchanged."""
    out = np.array(dofs, dtype=np.float64, copy=True)
    idx = _spherical_columns(skeleton.name)
    if idx.size:
        v = out[..., idx]  # (..., n_spherical, 3)
        big = np.einsum("...i,...i->...", v, v) > np.pi**2
        if big.any():
            out[..., idx] = np.where(big[..., None], rot.quat_to_expmap(rot.quat_from_expmap(v)), v)
    return out


def limit_targets(skeleton: Skeleton, dofs: np.ndarray) -> np.ndarray:
    """PD targets ``(..., n_dof)`` within ``joint_limits``: canonical exp maps, clipped angles."""
    low, high = joint_limits(skeleton)
    d = np.asarray(dofs, dtype=np.float64)
    if d.shape == low.shape and np.isfinite(d).all():  # one pose (every step's): compiled when nothing wraps
        from toolkit.motion import kernels

        out = np.empty_like(low)
        if kernels.clip_small_expmaps(d, _spherical_columns(skeleton.name), low, high, out):
            return out
    return np.clip(canonical_expmaps(skeleton, dofs), low, high)


def within_limits(skeleton: Skeleton, dofs: np.ndarray, tol: float = 1e-9) -> bool:
    """Whether every target of ``dofs`` ``(..., n_dof)`` lies within ``joint_limits`` (± ``tol``)."""
    low, high = joint_limits(skeleton)
    d = np.asarray(dofs)
    return bool(np.all(np.isfinite(d)) and np.all(d >= low - tol) and np.all(d <= high + tol))
