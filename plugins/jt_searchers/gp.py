"""Gaussian-process surrogate of the feature map g(x) for BDS (``000`` §5.1 eq 6, §6.1.5 eq 17).

Kernel ``theta * Matern52_ARD(x, x'; lengthscales) + eta^2 * delta`` (``001`` eq 3.17: Matérn 5/2 with
a learnable amplitude and one length scale per input dimension), prior mean = centre of each
feature's range (``000`` §6.1.5). Multi-output features share ONE kernel (one set of
hyperparameters, learned by maximising the log marginal likelihood summed over the outputs with
scikit-learn); each output is standardised as ``(f - centre) / half_range`` first, so the shared
amplitude and noise are in comparable units. The posterior standard deviation is therefore the same
for every standardised output, which gives BDS a single exploration acquisition sigma(x) (eq 9).

Hyperparameters are learned with scikit-learn; prediction (mean, std and the gradient of std, for
L-BFGS-B) is computed here in numpy from the same hyperparameters, so fantasised observations
(batch BDS) can be added without refitting.
"""

from __future__ import annotations

import warnings
from typing import Optional, Sequence

import numpy as np

SQRT5 = np.sqrt(5.0)


def matern52(a: np.ndarray, b: np.ndarray, lengthscales: np.ndarray, amplitude: float) -> np.ndarray:
    """Matérn 5/2 ARD kernel matrix ``(n, k)`` between ``a`` ``(n, d)`` and ``b`` ``(k, d)``."""
    diff = (a[:, None, :] - b[None, :, :]) / lengthscales
    r = np.sqrt(np.einsum("ntd,ntd->nt", diff, diff))
    return amplitude * (1.0 + SQRT5 * r + (5.0 / 3.0) * r * r) * np.exp(-SQRT5 * r)


def matern52_grad(x: np.ndarray, b: np.ndarray, lengthscales: np.ndarray, amplitude: float) -> np.ndarray:
    """Gradient of ``k(x, b_i)`` with respect to ``x`` ``(d,)`` for each row of ``b`` → ``(k, d)``.

    ``dk/dx = -(5/3) theta (1 + sqrt5 r) exp(-sqrt5 r) (x - b_i) / l^2`` (smooth at ``r = 0``).
    """
    diff = x[None, :] - b
    scaled = diff / lengthscales
    r = np.sqrt(np.sum(scaled * scaled, axis=-1))
    coef = -(5.0 / 3.0) * amplitude * (1.0 + SQRT5 * r) * np.exp(-SQRT5 * r)
    return coef[:, None] * diff / (lengthscales * lengthscales)


class FeatureGP:
    """GP posterior of a (multi-output) feature map over the unit cube.

    Args:
        dim: input dimension.
        centre: prior mean of each feature ``(m,)`` (centre of its range).
        half_range: scale of each feature ``(m,)`` (half its range).
        lengthscales: ARD length scales ``(dim,)``, in unit-cube units.
        amplitude: kernel variance theta (standardised units).
        noise: observation noise variance eta^2 (standardised units).
    """

    #: hyperparameter bounds used when fitting (unit cube inputs, standardised outputs)
    LENGTHSCALE_BOUNDS = (1e-2, 1e1)
    AMPLITUDE_BOUNDS = (1e-3, 1e2)
    NOISE_BOUNDS = (1e-6, 1e-1)
    JITTER = 1e-9

    def __init__(
        self,
        dim: int,
        centre: Sequence[float],
        half_range: Sequence[float],
        lengthscales: Optional[np.ndarray] = None,
        amplitude: float = 1.0,
        noise: float = 1e-3,
    ) -> None:
        self.dim = dim
        self.centre = np.asarray(centre, dtype=float)
        self.half_range = np.asarray(half_range, dtype=float)
        self.lengthscales = np.full(dim, 0.3) if lengthscales is None else np.asarray(lengthscales, float)
        self.amplitude = float(amplitude)
        self.noise = float(noise)
        self.U = np.zeros((0, dim))
        self.Y = np.zeros((0, len(self.centre)))

    # ---- data and hyperparameters -------------------------------------------------------------

    def standardise(self, F: np.ndarray) -> np.ndarray:
        """Raw features ``(n, m)`` → standardised ``(n, m)`` (prior mean subtracted)."""
        return (np.asarray(F, dtype=float) - self.centre) / self.half_range

    def fit(self, U: np.ndarray, F: np.ndarray, seed: int, n_restarts: int = 3) -> "FeatureGP":
        """Learn hyperparameters on ``U`` ``(n, dim)``, ``F`` ``(n, m)`` and condition on them.

        Uses scikit-learn's ``GaussianProcessRegressor`` (L-BFGS-B on the log marginal likelihood,
        ``n_restarts`` extra starts drawn with ``random_state=seed``), warm-started from the current
        hyperparameters. With fewer than two points the hyperparameters are kept as they are.
        """
        U = np.asarray(U, dtype=float).reshape(-1, self.dim)
        Y = self.standardise(F).reshape(len(U), -1)
        if len(U) >= 2:
            from sklearn.exceptions import ConvergenceWarning
            from sklearn.gaussian_process import GaussianProcessRegressor
            from sklearn.gaussian_process.kernels import ConstantKernel, Matern, WhiteKernel

            kernel = ConstantKernel(
                np.clip(self.amplitude, *self.AMPLITUDE_BOUNDS), self.AMPLITUDE_BOUNDS
            ) * Matern(
                length_scale=np.clip(self.lengthscales, *self.LENGTHSCALE_BOUNDS),
                length_scale_bounds=self.LENGTHSCALE_BOUNDS,
                nu=2.5,
            ) + WhiteKernel(np.clip(self.noise, *self.NOISE_BOUNDS), self.NOISE_BOUNDS)
            gpr = GaussianProcessRegressor(
                kernel=kernel,
                alpha=self.JITTER,
                normalize_y=False,
                n_restarts_optimizer=n_restarts,
                random_state=seed,
            )
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", ConvergenceWarning)
                gpr.fit(U, Y)
            k = gpr.kernel_
            self.amplitude = float(k.k1.k1.constant_value)
            self.lengthscales = np.broadcast_to(
                np.asarray(k.k1.k2.length_scale, dtype=float), (self.dim,)
            ).copy()
            self.noise = float(k.k2.noise_level)
        return self.condition(U, Y)

    def condition(self, U: np.ndarray, Y: np.ndarray) -> "FeatureGP":
        """Condition on standardised data ``U`` ``(n, dim)``, ``Y`` ``(n, m)`` (hyperparameters fixed)."""
        self.U = np.asarray(U, dtype=float).reshape(-1, self.dim)
        self.Y = np.asarray(Y, dtype=float).reshape(len(self.U), -1)
        K = matern52(self.U, self.U, self.lengthscales, self.amplitude)
        K[np.diag_indices_from(K)] += self.noise + self.JITTER
        self._L = np.linalg.cholesky(K) if len(K) else np.zeros((0, 0))
        self._alpha = self._solve(self.Y)
        self._Kinv = self._solve(np.eye(len(K)))  # small t: one (t, t) product per prediction
        return self

    def fantasise(self, u: np.ndarray) -> "FeatureGP":
        """A copy that also believes the posterior mean at ``u`` ``(dim,)`` (kriging believer)."""
        u = np.asarray(u, dtype=float).reshape(1, self.dim)
        mean = self.predict_standardised(u)[0]
        new = FeatureGP(self.dim, self.centre, self.half_range, self.lengthscales, self.amplitude, self.noise)
        return new.condition(np.vstack([self.U, u]), np.vstack([self.Y, mean]))

    def _solve(self, B: np.ndarray) -> np.ndarray:
        """``K^-1 B`` with the Cholesky factor."""
        from scipy.linalg import cho_solve

        if len(self.U) == 0:
            return np.zeros((0,) + B.shape[1:])
        return cho_solve((self._L, True), B)

    # ---- posterior ---------------------------------------------------------------------------------

    def predict_standardised(self, U: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Posterior at ``U`` ``(n, dim)``: standardised mean ``(n, m)`` and std ``(n,)``.

        The variance includes the observation noise, as ``000`` eq 6 writes it:
        ``sigma^2 = k(x, x) + eta^2 - k(X, x)^T (K + eta^2 I)^-1 k(X, x)``.
        """
        U = np.asarray(U, dtype=float).reshape(-1, self.dim)
        prior_var = self.amplitude + self.noise
        if len(self.U) == 0:
            return np.zeros((len(U), self.Y.shape[1])), np.full(len(U), np.sqrt(prior_var))
        Ks = matern52(U, self.U, self.lengthscales, self.amplitude)  # (n, t)
        mean = Ks @ self._alpha
        var = prior_var - np.einsum("nt,nt->n", Ks @ self._Kinv, Ks)
        return mean, np.sqrt(np.maximum(var, 1e-18))

    def predict(self, U: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Posterior at ``U`` ``(n, dim)`` in raw feature units: mean ``(n, m)``, std ``(n, m)``."""
        mean, std = self.predict_standardised(U)
        return self.centre + self.half_range * mean, std[:, None] * self.half_range

    def std_and_grad(self, u: np.ndarray) -> tuple[float, np.ndarray]:
        """Standardised posterior std at ``u`` ``(dim,)`` and its gradient ``(dim,)`` (eq 9)."""
        u = np.asarray(u, dtype=float).reshape(self.dim)
        if len(self.U) == 0:
            return float(np.sqrt(self.amplitude + self.noise)), np.zeros(self.dim)
        k = matern52(u[None], self.U, self.lengthscales, self.amplitude)[0]  # (t,)
        w = self._solve(k)  # K^-1 k
        var = max(self.amplitude + self.noise - float(k @ w), 1e-18)
        dk = matern52_grad(u, self.U, self.lengthscales, self.amplitude)  # (t, dim)
        std = np.sqrt(var)
        return std, -(w @ dk) / std  # d sigma = d var / (2 sigma), d var = -2 w^T dk

    def hyperparameters(self) -> dict[str, np.ndarray]:
        """The learned hyperparameters, for the run's HDF5."""
        return {
            "lengthscales": self.lengthscales.copy(),
            "amplitude": np.float64(self.amplitude),
            "noise": np.float64(self.noise),
            "prior_mean": self.centre.copy(),
            "feature_scale": self.half_range.copy(),
        }
