"""Joint limits of a character in the dof (PD-target) layout, and making targets respect them.

The dof layout (``Skeleton.dof_slices``) holds an exponential map per spherical joint and an angle
per revolute joint. Limits:

* revolute joints: the URDF's ``<limit lower upper>`` (humanoid knees ``[-3.14, 0]``, elbows
  ``[0, 3.14]``), read once with PyBullet's ``getJointInfo``;
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


@functools.lru_cache(maxsize=None)
def _limits(skeleton_name: str) -> tuple[np.ndarray, np.ndarray]:
    import pybullet as pb

    from toolkit.motion.kinematics import bullet_character

    sk = SKELETONS[skeleton_name]
    low, high = np.full(sk.n_dof, -np.pi), np.full(sk.n_dof, np.pi)
    with bullet_character(sk) as (cid, body):
        for j, s in zip(sk.joints, sk.dof_slices.values()):
            if j.kind == SPHERICAL:
                continue
            info = pb.getJointInfo(body, j.bullet_index, physicsClientId=cid)
            lo, hi = float(info[8]), float(info[9])
            if lo < hi:  # PyBullet reports lower > upper for a joint without limits
                low[s], high[s] = lo, hi
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
