"""Torch versions of the 6D rotation maps (for decoders trained with autograd).

Same conventions as ``rotations``: 6D = first two columns of ``R`` as ``(col0, col1)``. torch is
imported here only; nothing else in ``toolkit.motion`` imports this module.
"""

from __future__ import annotations

import torch


def sixd_to_matrix(d6: torch.Tensor, eps: float = 1e-12) -> torch.Tensor:
    """Gram-Schmidt of ``(..., 6)`` into rotation matrices ``(..., 3, 3)``, differentiable.

    Matches ``rotations.sixd_to_matrix`` for non-degenerate inputs (first column not ~0, columns
    not ~parallel), where the numpy version falls back to a fixed choice.
    """
    a1, a2 = d6[..., :3], d6[..., 3:]
    b1 = a1 / a1.norm(dim=-1, keepdim=True).clamp_min(eps)
    b2 = a2 - (b1 * a2).sum(dim=-1, keepdim=True) * b1
    b2 = b2 / b2.norm(dim=-1, keepdim=True).clamp_min(eps)
    b3 = torch.cross(b1, b2, dim=-1)
    return torch.stack([b1, b2, b3], dim=-1)


def matrix_to_sixd(m: torch.Tensor) -> torch.Tensor:
    """First two columns of ``(..., 3, 3)`` → ``(..., 6)``."""
    return torch.cat([m[..., :, 0], m[..., :, 1]], dim=-1)


def matrix_to_quat(m: torch.Tensor) -> torch.Tensor:
    """Canonical (``w >= 0``) quaternions ``x, y, z, w`` ``(..., 4)`` of rotation matrices
    ``(..., 3, 3)`` (Shepperd: the best-conditioned of four candidates per matrix)."""
    m00, m11, m22 = m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]
    cands = torch.stack(
        [
            torch.stack([1 + m00 - m11 - m22, m[..., 0, 1] + m[..., 1, 0],
                         m[..., 0, 2] + m[..., 2, 0], m[..., 2, 1] - m[..., 1, 2]], -1),
            torch.stack([m[..., 0, 1] + m[..., 1, 0], 1 - m00 + m11 - m22,
                         m[..., 1, 2] + m[..., 2, 1], m[..., 0, 2] - m[..., 2, 0]], -1),
            torch.stack([m[..., 0, 2] + m[..., 2, 0], m[..., 1, 2] + m[..., 2, 1],
                         1 - m00 - m11 + m22, m[..., 1, 0] - m[..., 0, 1]], -1),
            torch.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0],
                         m[..., 1, 0] - m[..., 0, 1], 1 + m00 + m11 + m22], -1),
        ],
        dim=-2,
    )  # fmt: skip
    k = torch.stack([m00 - m11 - m22, m11 - m00 - m22, m22 - m00 - m11, m00 + m11 + m22], -1).argmax(-1)
    q = torch.gather(cands, -2, k[..., None, None].expand(*k.shape, 1, 4)).squeeze(-2)
    q = q / q.norm(dim=-1, keepdim=True)
    return torch.where(q[..., 3:4] < 0, -q, q)


def sixd_to_quat(d6: torch.Tensor) -> torch.Tensor:
    """6D ``(..., 6)`` → canonical quaternions ``(..., 4)``."""
    return matrix_to_quat(sixd_to_matrix(d6))
