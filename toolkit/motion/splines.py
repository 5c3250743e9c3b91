"""Uniform cubic B-spline feature curves over normalised time (``003`` §4.1).

A curve ``p(s)``, ``s`` in ``[0, 1]``, is a cubic B-spline with uniformly spaced knots and (by
default) 9 control points (``003`` §4.1: "nine control points are sufficient"). The knot vector is
clamped (end knots repeated 4 times) so the curve starts at the first and ends at the last control
point — a get-up curve starts at the fallen value and ends at the standing value; ``clamped=False``
gives the unclamped cardinal B-spline over its valid span instead. Time maps to ``s`` by eq (1):
``s = min((t - t0) / T, 1)`` (also clamped below at 0 here).
"""

from __future__ import annotations

import dataclasses

import numpy as np

DEGREE = 3
N_CONTROL = 9  # 003 §4.1


def normalised_time(t, t0: float, duration: float) -> np.ndarray:
    """``s = clip((t - t0) / T, 0, 1)`` (``003`` eq 1) ``(...)``."""
    return np.clip((np.asarray(t, dtype=np.float64) - t0) / duration, 0.0, 1.0)


def uniform_knots(n_control: int, clamped: bool = True, degree: int = DEGREE) -> np.ndarray:
    """Knot vector ``(n_control + degree + 1,)`` whose valid span is ``[0, 1]``."""
    if n_control < degree + 1:
        raise ValueError(f"a degree-{degree} B-spline needs at least {degree + 1} control points, got {n_control}")
    if clamped:
        inner = np.linspace(0.0, 1.0, n_control - degree + 1)
        return np.concatenate([np.zeros(degree), inner, np.ones(degree)])
    n_span = n_control - degree
    return (np.arange(n_control + degree + 1) - degree) / n_span


def greville(n_control: int, clamped: bool = True, degree: int = DEGREE) -> np.ndarray:
    """Greville abscissae ``(n_control,)``: the ``s`` each control point is "attached" to."""
    k = uniform_knots(n_control, clamped, degree)
    return np.array([k[i + 1 : i + 1 + degree].mean() for i in range(n_control)])


def basis_matrix(s, knots: np.ndarray, degree: int = DEGREE) -> np.ndarray:
    """B-spline basis values ``(..., n_control)`` at ``s`` ``(...)`` (Cox-de Boor, vectorised).

    ``s`` is clamped to the valid span ``[knots[degree], knots[-degree-1]]``; the right end is
    included (the last basis function is 1 there for a clamped knot vector).
    """
    s = np.asarray(s, dtype=np.float64)
    lo, hi = knots[degree], knots[-degree - 1]
    s = np.clip(s, lo, hi)
    n_control = len(knots) - degree - 1
    # degree-0 bases: the span holding s (the last non-empty span owns s == hi)
    span = np.searchsorted(knots, s, side="right") - 1
    last = np.max(np.nonzero(knots[:-1] < knots[1:])[0])
    span = np.minimum(span, last)
    b = (np.arange(len(knots) - 1) == span[..., None]).astype(np.float64)
    for d in range(1, degree + 1):
        n = len(knots) - 1 - d
        left_den = knots[d : d + n] - knots[:n]
        right_den = knots[d + 1 : d + 1 + n] - knots[1 : 1 + n]
        with np.errstate(divide="ignore", invalid="ignore"):
            left = np.where(left_den > 0, (s[..., None] - knots[:n]) / left_den, 0.0)
            right = np.where(right_den > 0, (knots[d + 1 : d + 1 + n] - s[..., None]) / right_den, 0.0)
        b = left * b[..., :n] + right * b[..., 1 : n + 1]
    return b[..., :n_control]


@dataclasses.dataclass
class BSplineCurve:
    """A cubic B-spline over ``s`` in ``[0, 1]``.

    Attributes:
        control: control points ``(n_control,)`` or ``(n_control, dim)``.
        clamped: clamped (default) or unclamped uniform knots.
    """

    control: np.ndarray
    clamped: bool = True

    def __post_init__(self) -> None:
        self.control = np.asarray(self.control, dtype=np.float64)
        self._knots = uniform_knots(self.control.shape[0], self.clamped)

    @property
    def knots(self) -> np.ndarray:
        return self._knots.copy()

    def __call__(self, s) -> np.ndarray:
        """Curve values ``(...)`` or ``(..., dim)`` at ``s`` ``(...)`` (clamped to ``[0, 1]``).

        A number or a vector of ``s`` (the envs' per-step targets): the basis in one compiled call
        (``toolkit.motion.kernels.bspline_basis``), then ``tensordot``'s own product (the same bits)."""
        s = np.asarray(s, dtype=np.float64)
        if s.ndim <= 1 and np.isfinite(s).all():
            from toolkit.motion import kernels

            n = self.control.shape[0]
            b = np.empty((s.size, n))
            kernels.bspline_basis(s.reshape(-1), self._knots, DEGREE, b)
            out = np.dot(b, self.control.reshape(n, -1))  # what tensordot computes, reshaped
            return out.reshape(s.shape + self.control.shape[1:])
        b = basis_matrix(s, self._knots)
        return np.tensordot(b, self.control, axes=([-1], [0]))

    def at_time(self, t, t0: float, duration: float) -> np.ndarray:
        """Values at simulation times ``t`` of a motion starting at ``t0`` lasting ``duration``."""
        return self(normalised_time(t, t0, duration))

    @classmethod
    def from_samples(
        cls, s, values, n_control: int = N_CONTROL, clamped: bool = True, method: str = "sample"
    ) -> "BSplineCurve":
        """A curve from a feature sampled at ``s`` ``(n,)`` with ``values`` ``(n,)`` / ``(n, dim)``.

        Args:
            method: ``"sample"`` takes the control points as the feature sampled at ``n_control``
                instants (``003`` §4.1: "sampling them at nine equally distributed instances in
                time"; linear interpolation between the given samples): the Greville abscissae of
                the knots, equally spaced (1/6 apart for 9 clamped points) except next to the ends,
                where they are 1/18 from them so the curve reproduces any linear feature exactly;
                strictly equal spacing (1/8) would distort the curve near both ends.
                ``"lstsq"`` fits the control points by least squares to all samples.
        """
        s = np.asarray(s, dtype=np.float64)
        values = np.asarray(values, dtype=np.float64)
        order = np.argsort(s)
        s, values = s[order], values[order]
        if method == "sample":
            g = s[0] + (s[-1] - s[0]) * np.clip(greville(n_control, clamped), 0.0, 1.0)
            if values.ndim == 1:
                ctrl = np.interp(g, s, values)
            else:
                ctrl = np.stack([np.interp(g, s, values[:, k]) for k in range(values.shape[1])], axis=1)
            return cls(ctrl, clamped)
        if method == "lstsq":
            b = basis_matrix(s, uniform_knots(n_control, clamped))
            ctrl, *_ = np.linalg.lstsq(b, values, rcond=None)
            return cls(ctrl, clamped)
        raise ValueError(f"method must be 'sample' or 'lstsq', got {method!r}")
