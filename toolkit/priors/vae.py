"""The β-VAE of ``000`` §4.2 (and its conditional form, ``003`` §3.5) in torch, and its training.

Architecture (``000`` §4.2): encoder and decoder are fully connected, two hidden layers of 256
``tanh`` units; the encoder outputs the mean and log-variance of a diagonal Gaussian; the decoder's
last layer is linear. The C-VAE concatenates the condition ``c`` with the encoder's input and with
the decoder's latent input (``003`` §3.5).

Loss (``000`` eq 3): ``MSE(x, x') + β · KL(N(μ, Σ) || N(0, I))``. The MSE is the mean over batch
and features; the KL is **summed** over the batch and the latent dimensions. The paper does not
spell out the reductions; it says β = 1e-5 makes "the two terms ... within the same order of
magnitude numerically", which holds for a batch-summed KL (β · KL ~ 1e-2) and not for a
per-sample mean (~1e-4); the authors' public code reduces the same way.

Training: Adam, mini-batches of 128 drawn from a seeded permutation each epoch (the last, partial
batch kept), torch's default initialisation under ``torch.manual_seed(seed)``, one CPU thread, so
the same seed gives the same weights.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Callable, Optional

import numpy as np
import torch
from torch import nn


@dataclasses.dataclass(frozen=True)
class VAESettings:
    """Training settings (defaults: the P-VAE of ``000`` §4.2).

    Attributes:
        hidden: hidden layer sizes of the encoder (the decoder mirrors them).
        beta: KL weight β.
        lr: Adam learning rate.
        batch_size: mini-batch size.
        epochs: passes over the training set.
    """

    hidden: tuple[int, ...] = (256, 256)  # 000 §4.2
    beta: float = 1e-5  # 000 §4.2
    lr: float = 1e-4  # 000 §4.2
    batch_size: int = 128  # 000 §4.2
    epochs: int = 80  # 000 §4.2


#: the papers' settings per prior kind: P-VAE 000 §4.2, C-VAE 003 §3.5 (β = 1e-6, 100 epochs)
PAPER_SETTINGS = {
    "pvae": VAESettings(),
    "cvae": VAESettings(beta=1e-6, epochs=100),
}


class VAE(nn.Module):
    """β-VAE with an optional condition on encoder and decoder.

    Args:
        n_in: feature size.
        n_cond: condition size (0 = unconditional).
        latent_dim: latent size.
        hidden: hidden layer sizes.
    """

    def __init__(self, n_in: int, n_cond: int, latent_dim: int, hidden: tuple[int, ...] = (256, 256)) -> None:
        super().__init__()
        sizes = [n_in + n_cond, *hidden]
        self.enc = nn.ModuleList(nn.Linear(a, b) for a, b in zip(sizes[:-1], sizes[1:]))
        self.mu = nn.Linear(sizes[-1], latent_dim)
        self.logvar = nn.Linear(sizes[-1], latent_dim)
        dec = [latent_dim + n_cond, *reversed(hidden), n_in]
        self.dec = nn.ModuleList(nn.Linear(a, b) for a, b in zip(dec[:-1], dec[1:]))

    def encode(self, x: torch.Tensor, c: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Mean and log-variance ``(batch, latent_dim)``."""
        h = torch.cat([x, c], dim=-1)
        for layer in self.enc:
            h = torch.tanh(layer(h))
        return self.mu(h), self.logvar(h)

    def decode(self, z: torch.Tensor, c: torch.Tensor) -> torch.Tensor:
        """Normalised features ``(batch, n_in)``."""
        h = torch.cat([z, c], dim=-1)
        for layer in self.dec[:-1]:
            h = torch.tanh(layer(h))
        return self.dec[-1](h)

    def numpy_weights(self) -> dict[str, np.ndarray]:
        """Weights under the names ``toolkit.priors.model.PosePrior`` reads (float32)."""
        out: dict[str, np.ndarray] = {}
        for prefix, layers in (("enc", self.enc), ("dec", self.dec)):
            for i, layer in enumerate(layers):
                out[f"{prefix}{i}_w"] = layer.weight.detach().cpu().numpy().copy()
                out[f"{prefix}{i}_b"] = layer.bias.detach().cpu().numpy().copy()
        for name in ("mu", "logvar"):
            layer = getattr(self, name)
            out[f"{name}_w"] = layer.weight.detach().cpu().numpy().copy()
            out[f"{name}_b"] = layer.bias.detach().cpu().numpy().copy()
        return out


def kl_divergence(mu: torch.Tensor, logvar: torch.Tensor) -> torch.Tensor:
    """KL(N(mu, exp(logvar)) || N(0, I)) summed over batch and latent dims."""
    return -0.5 * torch.sum(1.0 + logvar - mu.pow(2) - logvar.exp())


@dataclasses.dataclass
class TrainResult:
    """What ``train_vae`` returns.

    Attributes:
        weights: numpy weights (see ``VAE.numpy_weights``).
        history: per-epoch means ``{"loss"|"recon_mse"|"kl": [(epoch, value), ...]}``.
        seconds: wall time of the training loop.
    """

    weights: dict[str, np.ndarray]
    history: dict[str, list[tuple[int, float]]]
    seconds: float


def train_vae(
    x: np.ndarray,
    c: Optional[np.ndarray],
    latent_dim: int,
    settings: VAESettings = VAESettings(),
    seed: int = 0,
    progress: Optional[Callable[[float, str], None]] = None,
) -> TrainResult:
    """Train a (C-)VAE on normalised features.

    Args:
        x: normalised training features ``(n, n_features)``.
        c: normalised conditions ``(n, n_cond)`` or ``None`` (P-VAE).
        latent_dim: latent size.
        settings: architecture and optimiser settings.
        seed: seeds initialisation, batch order and the reparameterisation noise.
        progress: optional ``progress(fraction, message)`` called once per epoch.
    """
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        torch.manual_seed(seed)
        gen = torch.Generator().manual_seed(seed)
        xt = torch.as_tensor(np.asarray(x, dtype=np.float32))
        ct = torch.as_tensor(np.asarray(c, dtype=np.float32)) if c is not None else torch.zeros(len(xt), 0)
        model = VAE(xt.shape[1], ct.shape[1], latent_dim, tuple(settings.hidden))
        opt = torch.optim.Adam(model.parameters(), lr=settings.lr)
        hist: dict[str, list[tuple[int, float]]] = {"loss": [], "recon_mse": [], "kl": []}
        n, bs = len(xt), int(settings.batch_size)
        t0 = time.perf_counter()
        for epoch in range(int(settings.epochs)):
            perm = torch.randperm(n, generator=gen)
            sums = np.zeros(3)
            n_batches = 0
            for start in range(0, n, bs):
                idx = perm[start : start + bs]
                xb, cb = xt[idx], ct[idx]
                mu, logvar = model.encode(xb, cb)
                eps = torch.randn(mu.shape, generator=gen)
                z = mu + eps * torch.exp(0.5 * logvar)
                mse = torch.mean((model.decode(z, cb) - xb) ** 2)
                kl = kl_divergence(mu, logvar)
                loss = mse + settings.beta * kl
                opt.zero_grad()
                loss.backward()
                opt.step()
                sums += (loss.item(), mse.item(), kl.item())
                n_batches += 1
            for key, v in zip(("loss", "recon_mse", "kl"), sums / max(n_batches, 1)):
                hist[key].append((epoch, float(v)))
            if progress is not None:
                msg = f"epoch {epoch + 1}/{settings.epochs} loss {sums[0] / n_batches:.4g}"
                progress((epoch + 1) / settings.epochs, msg)
        seconds = time.perf_counter() - t0
        return TrainResult(model.numpy_weights(), hist, seconds)
    finally:
        torch.set_num_threads(threads)
