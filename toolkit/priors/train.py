"""Fit a pose prior on a pose dataset: normalise, pick the latent size by PCA, train, evaluate.

``fit_prior`` is what ``task=pose_prior`` runs. Reconstruction errors are reported in the
**normalised feature units** the VAE is trained in (per-column z-scores of the training set), for
the VAE (decode of the encoder mean) and for PCA with the same number of components fitted on the
same normalised training features, so the two numbers compare directly. Joint-rotation errors in
radians (mean over joints and frames of the angle between true and reconstructed rotations) are
reported beside them.
"""

from __future__ import annotations

import contextlib
import dataclasses
from typing import Any, Callable, Iterator, Optional

import numpy as np

from toolkit.motion import rotations as rot
from toolkit.motion.features import FeatureLayout, features_to_joints
from toolkit.motion.skeletons import SKELETONS, SPHERICAL, Skeleton
from toolkit.priors.model import KINDS, PosePrior
from toolkit.priors.pca import DEFAULT_VARIANCE, fit_pca, rmse

STD_FLOOR = 1e-8  # columns with a smaller std are constant: they keep std 1


@contextlib.contextmanager
def single_thread() -> Iterator[None]:
    """BLAS (numpy) limited to one thread: reproducible sums, and no thread thrashing on a busy
    machine (a 1954 x 147 SVD takes 0.08 s on one thread and over 1 s on two contended ones)."""
    try:
        from threadpoolctl import threadpool_limits  # ships with scikit-learn
    except ImportError:  # pragma: no cover
        yield
        return
    with threadpool_limits(limits=1):
        yield


def normalizer(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-column mean and std ``(d,)`` of ``x`` ``(n, d)``; constant columns get std 1."""
    x = np.asarray(x, dtype=np.float64)
    mean, std = x.mean(axis=0), x.std(axis=0)
    return mean, np.where(std < STD_FLOOR, 1.0, std)


def rotation_error(skeleton: Skeleton, joints_a: np.ndarray, joints_b: np.ndarray) -> float:
    """Mean angle (rad) between two sets of joint rotations in the quaternion layout ``(n, n_q)``
    (rotation angle for spherical joints, absolute angle difference for revolute ones)."""
    errs = []
    for j, s in zip(skeleton.joints, skeleton.q_slices.values()):
        if j.kind == SPHERICAL:
            errs.append(rot.quat_angle(joints_a[..., s], joints_b[..., s]))
        else:
            errs.append(np.abs(joints_a[..., s.start] - joints_b[..., s.start]))
    return float(np.mean(np.stack(errs, axis=-1))) if joints_a.size else float("nan")


@dataclasses.dataclass
class FitResult:
    """What ``fit_prior`` returns: the prior (with its metrics) and the training curves."""

    prior: PosePrior
    history: dict[str, list[tuple[int, float]]]


def fit_prior(
    kind: str,
    layout: FeatureLayout,
    train_x: np.ndarray,
    train_c: np.ndarray | None = None,
    held_x: np.ndarray | None = None,
    held_c: np.ndarray | None = None,
    settings: Any = None,
    variance: float = DEFAULT_VARIANCE,
    latent_dim: int = 0,
    seed: int = 0,
    condition_names: tuple[str, ...] = (),
    info: Optional[dict] = None,
    progress: Optional[Callable[[float, str], None]] = None,
) -> FitResult:
    """Train a P-VAE (``kind="pvae"``) or C-VAE (``"cvae"``) and measure it against PCA.

    Args:
        kind: ``"pvae"`` or ``"cvae"``.
        layout: layout of the feature columns.
        train_x: training pose features ``(n, n_features)``.
        train_c: training conditions ``(n, n_cond)`` (C-VAE).
        held_x: held-out features ``(m, n_features)`` (may be empty / ``None``).
        held_c: held-out conditions ``(m, n_cond)``.
        settings: ``VAESettings``; the paper's for ``kind`` when ``None``.
        variance: variance fraction that fixes the latent size by PCA (``000`` §4.2: 0.85).
        latent_dim: a fixed latent size instead (0 = by PCA).
        seed: training seed.
        condition_names: names of the condition entries (stored with the prior).
        info: provenance stored with the prior.
        progress: ``progress(fraction, message)``.
    """
    with single_thread():
        return _fit(kind, layout, train_x, train_c, held_x, held_c, settings, variance, latent_dim, seed,
                    condition_names, info, progress)  # fmt: skip


def _fit(kind, layout, train_x, train_c, held_x, held_c, settings, variance, latent_dim, seed,  # noqa: ANN001
         condition_names, info, progress) -> FitResult:  # fmt: skip
    from toolkit.priors.vae import PAPER_SETTINGS, train_vae

    if kind not in KINDS:
        raise ValueError(f"unknown prior kind {kind!r}; expected one of {KINDS}")
    settings = settings or PAPER_SETTINGS[kind]
    conditional = kind == "cvae"
    if conditional and train_c is None:
        raise ValueError("a C-VAE needs training conditions")
    x_mean, x_std = normalizer(train_x)
    xn = (train_x - x_mean) / x_std
    if conditional:
        c_mean, c_std = normalizer(train_c)
        cn = (train_c - c_mean) / c_std
    else:
        c_mean = c_std = np.zeros(0)
        cn = None

    pca = fit_pca(xn)
    pca_dim = pca.n_components(variance)
    k = int(latent_dim) or pca_dim
    result = train_vae(xn, cn, k, settings, seed, progress)
    prior = PosePrior(
        kind=kind, layout=layout, latent_dim=k, weights=result.weights, x_mean=x_mean, x_std=x_std,
        c_mean=c_mean, c_std=c_std, z_mean=np.zeros(k), z_std=np.ones(k),
        condition_names=tuple(condition_names) if conditional else (), info=dict(info or {}),
    )  # fmt: skip
    mu, _ = prior.encode(train_x, train_c if conditional else None)
    prior.z_mean, prior.z_std = mu.mean(axis=0), np.maximum(mu.std(axis=0), 1e-6)

    sk = SKELETONS[layout.skeleton]
    m: dict[str, float] = {
        "latent_dim": float(k), "pca_latent_dim": float(pca_dim),
        "pca_variance_at_latent": float(pca.explained_ratio[k - 1]),
        "n_train": float(len(train_x)), "n_heldout": float(0 if held_x is None else len(held_x)),
        "train_seconds": result.seconds, "final_loss": result.history["loss"][-1][1],
        "final_recon_mse": result.history["recon_mse"][-1][1], "final_kl": result.history["kl"][-1][1],
    }  # fmt: skip
    splits = {"train": (train_x, train_c)}
    if held_x is not None and len(held_x):
        splits["heldout"] = (held_x, held_c)
    for name, (x, c) in splits.items():
        recon = prior.reconstruct(x, c if conditional else None)
        lin = prior.denormalize(pca.reconstruct(prior.normalize(x), k))
        m[f"recon_rmse_{name}"] = rmse(prior.normalize(recon), prior.normalize(x))
        m[f"pca_rmse_{name}"] = rmse(pca.reconstruct(prior.normalize(x), k), prior.normalize(x))
        truth = features_to_joints(x, layout)
        m[f"recon_rot_err_{name}"] = rotation_error(sk, features_to_joints(recon, layout), truth)
        m[f"pca_rot_err_{name}"] = rotation_error(sk, features_to_joints(lin, layout), truth)
    if "heldout" not in splits:
        for key in ("recon_rmse", "pca_rmse", "recon_rot_err", "pca_rot_err"):
            m[f"{key}_heldout"] = float("nan")
    prior.metrics = m
    prior.info.setdefault("settings", dataclasses.asdict(settings))
    prior.info.setdefault("variance", variance)
    prior.info.setdefault("seed", int(seed))
    return FitResult(prior, result.history)
