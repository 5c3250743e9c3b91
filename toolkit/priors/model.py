"""A trained pose prior (P-VAE ``000`` §4.2 or C-VAE ``003`` §3.5), evaluated in numpy.

The VAE reconstructs the **full pose feature** (``000`` §4.2: "the decoder maps a latent vector
... back to the original feature space"); PD targets are then read off its 6D rotation blocks
(``features_to_joints``: Gram-Schmidt per spherical joint, the angle about the axis per revolute
one) and converted to the dof layout (exp maps, angles) with ``Skeleton.joints_to_dofs``. The
positions in the feature are not used at run time.

Everything a decoder needs travels with the model: the feature normalisation (per-column mean and
std of the training features; constant columns get std 1), the condition normalisation (C-VAE),
the feature layout, and the statistics of the encoder means over the training set, which
*whiten* the policy's latent action: ``z = z_mean + z_std * a_latent`` (as the authors' public
code does), so an action of 0 decodes the centre of the data's latent cloud and a unit action is
one standard deviation of it. Inference is plain numpy (float64) and batched over leading dims;
torch is only needed to train (``toolkit.priors.vae``).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from toolkit.motion import rotations as rot
from toolkit.motion.features import FeatureLayout
from toolkit.motion.skeletons import SKELETONS, SPHERICAL, Skeleton

KINDS = ("pvae", "cvae")


def mlp(x: np.ndarray, weights: list[tuple[np.ndarray, np.ndarray]], last_linear: bool = True) -> np.ndarray:
    """Fully connected net: ``tanh`` after every layer but (if ``last_linear``) the last.

    Args:
        x: inputs ``(..., n_in)``.
        weights: ``(W, b)`` per layer, ``W`` ``(n_out, n_in)`` as torch's ``Linear`` stores it.
        last_linear: leave the last layer's output without activation.
    """
    h = x
    for i, (w, b) in enumerate(weights):
        h = h @ w.T + b
        if i < len(weights) - 1 or not last_linear:
            h = np.tanh(h)
    return h


def _f64(w: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """float64 copies (``W`` laid out so that ``W.T`` is C-contiguous for the ``h @ W.T`` products)."""
    return np.asfortranarray(np.asarray(w, dtype=np.float64)), np.asarray(b, dtype=np.float64)


def _layers(weights: dict[str, np.ndarray], prefix: str) -> list[tuple[np.ndarray, np.ndarray]]:
    out, i = [], 0
    while f"{prefix}{i}_w" in weights:
        out.append(_f64(weights[f"{prefix}{i}_w"], weights[f"{prefix}{i}_b"]))
        i += 1
    return out


class TargetMap:
    """Pose features → PD targets for every joint at once (``features_to_joints`` followed by
    ``joints_to_dofs``, vectorised over the joints: ~20x faster for one pose).

    Args:
        layout: the feature layout (its skeleton's joints all need a ``rot6d`` block).
    """

    def __init__(self, layout: FeatureLayout) -> None:
        sk = SKELETONS[layout.skeleton]
        self.skeleton = sk
        cols = [np.arange(layout.block(j.name, "rot6d").start, layout.block(j.name, "rot6d").stop) for j in sk.joints]
        self.cols = np.stack(cols)  # (n_joints, 6)
        dofs = list(sk.dof_slices.values())
        self.sph = np.array([i for i, j in enumerate(sk.joints) if j.kind == SPHERICAL], dtype=int)
        self.rev = np.array([i for i, j in enumerate(sk.joints) if j.kind != SPHERICAL], dtype=int)
        self.sph_dofs = np.concatenate([np.arange(dofs[i].start, dofs[i].stop) for i in self.sph] or [np.zeros(0, int)])
        self.rev_dofs = np.array([dofs[i].start for i in self.rev], dtype=int)
        axes, es, fs = [], [], []
        for i in self.rev:  # the angle about the axis, as features_to_joints measures it
            a = np.asarray(sk.joints[i].axis, dtype=np.float64)
            e = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
            e /= np.linalg.norm(e)
            axes.append(a), es.append(e), fs.append(np.cross(a, e))
        self.e = np.array(es).reshape(-1, 3)
        self.f = np.array(fs).reshape(-1, 3)
        self._sph_dofs = self.sph_dofs.reshape(-1, 3)

    def __call__(self, features: np.ndarray) -> np.ndarray:
        """PD targets ``(..., n_dof)`` from raw features ``(..., n_features)``: one pose (an env's
        step) through the compiled kernel, a batch vectorised in numpy (the same bits)."""
        x = np.asarray(features, dtype=np.float64)
        if x.ndim == 1:
            from toolkit.motion.kernels import features_to_dofs_post, features_to_dofs_pre

            quat, ys, xs = np.empty((len(self.sph), 4)), np.empty(len(self.cols)), np.empty(len(self.cols))
            features_to_dofs_pre(np.ascontiguousarray(x), self.cols, self.sph, self.rev, self.e, self.f, rot.EPS,
                                 quat, ys, xs)
            out = np.empty(self.skeleton.n_dof)
            features_to_dofs_post(quat, np.arctan2(ys, xs), self._sph_dofs, self.rev_dofs, out)
            return out
        m = rot.sixd_to_matrix(x[..., self.cols])  # (..., n_joints, 3, 3)
        out = np.empty(x.shape[:-1] + (self.skeleton.n_dof,))
        lead = x.shape[:-1]
        if len(self.sph):
            v = rot.quat_to_expmap(rot.matrix_to_quat(m[..., self.sph, :, :]))  # (..., n_sph, 3)
            out[..., self.sph_dofs] = v.reshape(lead + (-1,))
        if len(self.rev):
            re = np.einsum("...kij,kj->...ki", m[..., self.rev, :, :], self.e)
            out[..., self.rev_dofs] = np.arctan2(np.sum(re * self.f, -1), np.sum(re * self.e, -1))
        return out


@dataclasses.dataclass
class PosePrior:
    """A trained P-VAE / C-VAE with its normalisation and layout.

    Attributes:
        kind: ``"pvae"`` or ``"cvae"``.
        layout: the pose-feature layout the model was trained on.
        latent_dim: latent size.
        weights: ``enc{i}_w/b`` (hidden encoder layers), ``mu_w/b``, ``logvar_w/b``, ``dec{i}_w/b``
            (decoder layers, the last one linear); ``W`` ``(n_out, n_in)``.
        x_mean: feature mean ``(n_features,)``.
        x_std: feature std ``(n_features,)``.
        c_mean: condition mean ``(n_cond,)`` (empty for a P-VAE).
        c_std: condition std ``(n_cond,)``.
        z_mean: mean of the encoder means over the training set ``(latent_dim,)``.
        z_std: their std ``(latent_dim,)``.
        condition_names: names of the condition entries (C-VAE).
        metrics: training and evaluation numbers (``latent_dim``, ``recon_rmse_heldout``, ...).
        info: provenance: training settings, data set, seed (JSON-able).
    """

    kind: str
    layout: FeatureLayout
    latent_dim: int
    weights: dict[str, np.ndarray]
    x_mean: np.ndarray
    x_std: np.ndarray
    c_mean: np.ndarray
    c_std: np.ndarray
    z_mean: np.ndarray
    z_std: np.ndarray
    condition_names: tuple[str, ...] = ()
    metrics: dict[str, float] = dataclasses.field(default_factory=dict)
    info: dict[str, Any] = dataclasses.field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"unknown prior kind {self.kind!r}; expected one of {KINDS}")
        self._enc = _layers(self.weights, "enc")
        self._dec = _layers(self.weights, "dec")
        self._mu = _f64(self.weights["mu_w"], self.weights["mu_b"])
        self._logvar = _f64(self.weights["logvar_w"], self.weights["logvar_b"])
        self._targets = TargetMap(self.layout)

    # ---- shapes ----------------------------------------------------------------------------
    @property
    def skeleton(self) -> Skeleton:
        return SKELETONS[self.layout.skeleton]

    @property
    def n_features(self) -> int:
        return int(self.x_mean.shape[0])

    @property
    def n_cond(self) -> int:
        return int(self.c_mean.shape[0])

    @property
    def conditional(self) -> bool:
        return self.kind == "cvae"

    # ---- normalisation ---------------------------------------------------------------------
    def normalize(self, x: np.ndarray) -> np.ndarray:
        """Raw features ``(..., n_features)`` → the network's units."""
        return (np.asarray(x, dtype=np.float64) - self.x_mean) / self.x_std

    def denormalize(self, xn: np.ndarray) -> np.ndarray:
        """Network units → raw features ``(..., n_features)``."""
        return np.asarray(xn, dtype=np.float64) * self.x_std + self.x_mean

    def _cond(self, c: np.ndarray | None, lead: tuple[int, ...]) -> np.ndarray:
        if not self.conditional:
            return np.zeros(lead + (0,))
        if c is None:
            raise ValueError("a C-VAE needs a condition c = (h, theta_side, theta_front)")
        c = np.asarray(c, dtype=np.float64)
        if c.shape[-1] != self.n_cond:
            raise ValueError(f"condition must have {self.n_cond} entries, got shape {c.shape}")
        return np.broadcast_to((c - self.c_mean) / self.c_std, lead + (self.n_cond,))

    # ---- the networks ----------------------------------------------------------------------
    def encode(self, x: np.ndarray, c: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Mean and log-variance ``(..., latent_dim)`` of q(z | x, c) for raw features ``x``."""
        xn = self.normalize(x)
        h = np.concatenate([xn, self._cond(c, xn.shape[:-1])], axis=-1)
        h = mlp(h, self._enc, last_linear=False) if self._enc else h
        return h @ self._mu[0].T + self._mu[1], h @ self._logvar[0].T + self._logvar[1]

    def decode(self, z: np.ndarray, c: np.ndarray | None = None) -> np.ndarray:
        """Raw pose features ``(..., n_features)`` decoded from latents ``z`` ``(..., latent_dim)``."""
        z = np.asarray(z, dtype=np.float64)
        if z.shape[-1] != self.latent_dim:
            raise ValueError(f"latent must have {self.latent_dim} entries, got shape {z.shape}")
        h = np.concatenate([z, self._cond(c, z.shape[:-1])], axis=-1)
        return self.denormalize(mlp(h, self._dec))

    def reconstruct(self, x: np.ndarray, c: np.ndarray | None = None) -> np.ndarray:
        """Decode of the encoder mean: the deterministic reconstruction ``(..., n_features)``."""
        return self.decode(self.encode(x, c)[0], c)

    def latent_from_action(self, a: np.ndarray) -> np.ndarray:
        """Whitened latent action ``(..., latent_dim)`` → latent ``z_mean + z_std * a``."""
        return self.z_mean + self.z_std * np.asarray(a, dtype=np.float64)

    def decode_targets(self, z: np.ndarray, c: np.ndarray | None = None) -> np.ndarray:
        """PD targets in the dof layout ``(..., n_dof)`` (exp maps, angles): ``D_pose(z)``."""
        return self._targets(self.decode(z, c))
