"""PCA of pose features: the latent size of the pose priors and their linear baseline.

``000`` §4.2 chooses the P-VAE latent size as the number of principal components covering 85 % of
the training data's variance (13 on its CMU + SFU poses); ``003`` §3.5 does the same for the C-VAE
(16 on LAFAN1). ``Pca`` is fitted by an SVD of the centred data (numpy only).
"""

from __future__ import annotations

import dataclasses

import numpy as np

DEFAULT_VARIANCE = 0.85  # 000 §4.2, 003 §3.5


@dataclasses.dataclass(frozen=True)
class Pca:
    """Principal components of a data set.

    Attributes:
        mean: data mean ``(d,)``.
        components: principal directions, rows, by decreasing variance ``(r, d)``.
        variance: variance along each component ``(r,)``.
    """

    mean: np.ndarray
    components: np.ndarray
    variance: np.ndarray

    @property
    def explained_ratio(self) -> np.ndarray:
        """Cumulative fraction of the total variance covered by the first k components ``(r,)``."""
        total = float(self.variance.sum())
        return np.cumsum(self.variance) / total if total > 0 else np.ones_like(self.variance)

    def n_components(self, fraction: float = DEFAULT_VARIANCE) -> int:
        """Smallest k whose components cover at least ``fraction`` of the variance."""
        if not 0.0 < fraction <= 1.0:
            raise ValueError(f"variance fraction must be in (0, 1], got {fraction}")
        ratio = self.explained_ratio
        return int(min(np.searchsorted(ratio, fraction - 1e-12) + 1, len(ratio)))

    def project(self, x: np.ndarray, k: int) -> np.ndarray:
        """Coordinates ``(n, k)`` of ``x`` ``(n, d)`` on the first k components."""
        return (np.asarray(x, dtype=np.float64) - self.mean) @ self.components[:k].T

    def reconstruct(self, x: np.ndarray, k: int) -> np.ndarray:
        """``x`` ``(n, d)`` projected on the first k components and back ``(n, d)``."""
        return self.mean + self.project(x, k) @ self.components[:k]


def fit_pca(x: np.ndarray) -> Pca:
    """PCA of the rows of ``x`` ``(n, d)`` (population variance, divisor n)."""
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 2 or x.shape[0] < 2:
        raise ValueError(f"PCA needs a 2-D array with at least two rows, got shape {x.shape}")
    mean = x.mean(axis=0)
    _, s, vt = np.linalg.svd(x - mean, full_matrices=False)
    return Pca(mean=mean, components=vt, variance=s**2 / x.shape[0])


def rmse(a: np.ndarray, b: np.ndarray) -> float:
    """Root mean squared difference over every element."""
    d = np.asarray(a, dtype=np.float64) - np.asarray(b, dtype=np.float64)
    return float(np.sqrt(np.mean(d**2))) if d.size else float("nan")
