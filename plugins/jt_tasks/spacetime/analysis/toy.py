"""Fig. 2's toy (002 §3.1, eq 1): feasible regions of a mass point under spacetime bounds, in closed form.

A mass point on the x axis, state ``(x, v)``, acceleration ``|a| <= a_max`` (2 m/s², 002 §3.1).
Events and bounds are axis-aligned boxes in ``(x, v)`` at one time each (``Box``; an event is a
box of zero size). The feasible region at time ``t`` (002 Definition 3.2) is the set of states on
causal trajectories from the start event to the end event that pass every bound::

    Feasible(t) = Forward(t) ∩ Backward(t) ∩ (the bound at t, if any)

``Forward(t)``: the states reachable at ``t`` from the start through every bound before ``t``;
``Backward(t)``: the states from which the end is reachable through every bound after ``t``.

Computed in closed form, not on a grid: the double integrator is linear, so a reachable set is
convex, ``Forward(t0 + τ) = A(τ) S ⊕ R(τ)`` for a set ``S`` at ``t0``, with the shear
``A(τ): (x, v) -> (x + v τ, v)`` and ``R(τ)`` the set reachable from rest at the origin. ``R(τ)``
is bounded by the two bang-bang arcs (one switch: ``+a`` then ``-a`` gives the largest ``x`` for
a final ``v``, the mirror the smallest), from ``(-a τ²/2, -a τ)`` to ``(a τ²/2, a τ)``; it is
symmetric, so ``Backward(t1 - τ) = A(-τ)(Q ⊕ R(τ))`` for a set ``Q`` at ``t1``. Sets are convex
polygons ``(n, 2)`` (counter-clockwise, columns ``x, v``) whose vertices lie on the exact
boundary (``n_arc`` points per arc), so each is inscribed in the exact set (64 per arc: within
about 5e-4 m of it, error falling as ``1 / n_arc²``): Minkowski sums by merging edges, bounds by
clipping (Sutherland–Hodgman). Fig. 2's 3 x 29 regions take about 1 s, the figure 2 s more.

The paper's setting (002 §3.1): ``e1 = (0, 0)`` at ``t = 0``, ``e2 = (0, 0)`` at ``t = 5``,
``b1``: ``x ∈ [0.5, 2.5]``, ``v ∈ [-1, 1]`` at ``T1 = 5/3``, ``b2``: ``x ∈ [-2.5, -0.5]``,
``v ∈ [-1, 1]`` at ``T2 = 10/3`` (eq 1). The figure's view (3-D slices) is ours; the paper
gives only the sets. ::

    jt study spacetime toy --out DIR     # DIR/fig2_toy.png
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Optional, Sequence

import numpy as np

from toolkit.errors import one_line_errors
from toolkit.study import parser, writable_folder

PROG = "jt study spacetime toy"

A_MAX = 2.0
"""m/s², the acceleration cap (002 §3.1)."""


@dataclasses.dataclass(frozen=True)
class Box:
    """A spacetime bound (or, of zero size, an event): ``x ∈ [x0, x1]``, ``v ∈ [v0, v1]`` at ``t``."""

    t: float
    x: tuple[float, float]
    v: tuple[float, float]

    def polygon(self) -> np.ndarray:
        """The box's corners ``(4, 2)`` counter-clockwise (one row for a point)."""
        (x0, x1), (v0, v1) = self.x, self.v
        pts = np.array([[x0, v0], [x1, v0], [x1, v1], [x0, v1]], dtype=float)
        return pts[:1] if x0 == x1 and v0 == v1 else pts


E1 = Box(0.0, (0.0, 0.0), (0.0, 0.0))
E2 = Box(5.0, (0.0, 0.0), (0.0, 0.0))
B1 = Box(5.0 / 3.0, (0.5, 2.5), (-1.0, 1.0))
B2 = Box(10.0 / 3.0, (-2.5, -0.5), (-1.0, 1.0))
#: the three panels of 002 Fig. 2: the bounds between e1 and e2
PAPER_CASES: dict[str, tuple[Box, ...]] = {"B = {e1, e2}": (), "+ b1": (B1,), "+ b1, b2": (B1, B2)}
EMPTY = np.zeros((0, 2))
T_TOL = 1e-9
"""s: a bound this close to the asked time is the bound *at* that time."""


def reach_from_rest(tau: float, a_max: float = A_MAX, n_arc: int = 64) -> np.ndarray:
    """``R(τ)``: the states reachable from ``(0, 0)`` in ``τ`` s, a polygon on its exact boundary
    (``2 n_arc - 2`` vertices, counter-clockwise; one row for ``τ = 0``)."""
    if tau <= 0.0:
        return np.zeros((1, 2))
    v = np.linspace(-a_max * tau, a_max * tau, int(n_arc))
    t1 = 0.5 * (tau + v / a_max)  # time at +a before switching to -a
    t2 = tau - t1
    x_max = a_max * (0.5 * t1 ** 2 + t1 * t2 - 0.5 * t2 ** 2)
    right = np.column_stack([x_max, v])  # v ascending
    left = -right  # x_min(v) = -x_max(-v): v descending
    return np.vstack([right, left[1:-1]])


def shear(poly: np.ndarray, tau: float) -> np.ndarray:
    """``A(τ) P``: every state coasted ``τ`` s (``x + v τ``); ``τ < 0`` coasts backwards."""
    out = np.array(poly, dtype=float)
    out[:, 0] += out[:, 1] * tau
    return out


def minkowski(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``P ⊕ Q`` of two counter-clockwise convex polygons (edge vectors merged by angle)."""
    if len(p) == 0 or len(q) == 0:
        return EMPTY
    if len(p) == 1 or len(q) == 1:
        return (q + p[0]) if len(p) == 1 else (p + q[0])

    def lowest_first(a: np.ndarray) -> np.ndarray:
        i = np.lexsort((a[:, 0], a[:, 1]))[0]
        return np.roll(a, -i, axis=0)

    p, q = lowest_first(p), lowest_first(q)
    edges = np.vstack([np.roll(p, -1, axis=0) - p, np.roll(q, -1, axis=0) - q])
    angle = np.mod(np.arctan2(edges[:, 1], edges[:, 0]), 2 * np.pi)
    walk = np.cumsum(edges[np.argsort(angle, kind="stable")], axis=0)
    return np.vstack([p[0] + q[0], p[0] + q[0] + walk[:-1]])


def clip(poly: np.ndarray, convex: np.ndarray, eps: float = 1e-12) -> np.ndarray:
    """``P ∩ C`` for a polygon ``P`` and a counter-clockwise convex polygon ``C`` of >= 3 vertices
    (Sutherland–Hodgman); ``(0, 2)`` when empty."""
    out = np.asarray(poly, dtype=float)
    for a, b in zip(convex, np.roll(convex, -1, axis=0)):
        if len(out) == 0:
            break
        d = b - a
        side = d[0] * (out[:, 1] - a[1]) - d[1] * (out[:, 0] - a[0])  # > 0: left of a -> b (inside)
        inside = side >= -eps
        prev, prev_side, prev_in = np.roll(out, 1, axis=0), np.roll(side, 1), np.roll(inside, 1)
        cross = inside != prev_in  # the edge prev -> this vertex crosses the line: its crossing point
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.where(cross, prev_side / (prev_side - side), 0.0)
        hit = prev + s[:, None] * (out - prev)
        both = np.stack([hit, out], axis=1).reshape(-1, 2)  # per vertex: [crossing, vertex]
        out = both[np.stack([cross, inside], axis=1).reshape(-1)]
    return out


def area(poly: np.ndarray) -> float:
    """Area of a polygon (shoelace; 0 for fewer than 3 vertices)."""
    if len(poly) < 3:
        return 0.0
    x, v = poly[:, 0], poly[:, 1]
    return 0.5 * abs(float(x @ np.roll(v, -1) - v @ np.roll(x, -1)))


def _through(poly: np.ndarray, box: Box) -> np.ndarray:
    return clip(poly, box.polygon()) if len(poly) else EMPTY


def forward(t: float, start: Box, bounds: Sequence[Box], a_max: float = A_MAX, n_arc: int = 64) -> np.ndarray:
    """States reachable at ``t`` from ``start`` through every bound before ``t``."""
    s, t_prev = start.polygon(), start.t
    for b in sorted(bounds, key=lambda b: b.t):
        if b.t >= t - T_TOL:
            break
        s = _through(minkowski(shear(s, b.t - t_prev), reach_from_rest(b.t - t_prev, a_max, n_arc)), b)
        t_prev = b.t
    return minkowski(shear(s, t - t_prev), reach_from_rest(t - t_prev, a_max, n_arc)) if len(s) else EMPTY


def backward(t: float, end: Box, bounds: Sequence[Box], a_max: float = A_MAX, n_arc: int = 64) -> np.ndarray:
    """States at ``t`` from which ``end`` is reachable through every bound after ``t``."""
    s, t_next = end.polygon(), end.t
    for b in sorted(bounds, key=lambda b: -b.t):
        if b.t <= t + T_TOL:
            break
        s = _through(shear(minkowski(s, reach_from_rest(t_next - b.t, a_max, n_arc)), b.t - t_next), b)
        t_next = b.t
    return shear(minkowski(s, reach_from_rest(t_next - t, a_max, n_arc)), t - t_next) if len(s) else EMPTY


def feasible(t: float, start: Box = E1, end: Box = E2, bounds: Sequence[Box] = (), a_max: float = A_MAX,
             n_arc: int = 64) -> np.ndarray:
    """``Feasible(t)`` (002 Definition 3.2) for ``start.t < t < end.t``: a convex polygon ``(n, 2)``
    (columns ``x, v``), ``(0, 2)`` when no causal trajectory passes every bound."""
    f = forward(t, start, bounds, a_max, n_arc)
    g = backward(t, end, bounds, a_max, n_arc)
    region = clip(f, g) if len(f) >= 3 and len(g) >= 3 else EMPTY
    for b in bounds:
        if abs(b.t - t) <= T_TOL and len(region):
            region = clip(region, b.polygon())
    return region


def toy_regions(times: Optional[Sequence[float]] = None, cases: Optional[dict[str, tuple[Box, ...]]] = None,
                n_arc: int = 64) -> dict[str, list[np.ndarray]]:
    """The feasible regions of each case (default: 002 Fig. 2's three) at ``times`` (default: 29
    times inside ``(0, 5)``, the bounds' times among them): ``{case: [polygon per time]}``."""
    times = default_times() if times is None else times
    cases = PAPER_CASES if cases is None else cases
    return {name: [feasible(float(t), E1, E2, bounds, A_MAX, n_arc) for t in times] for name, bounds in cases.items()}


def default_times(n_steps: int = 30) -> np.ndarray:
    """The ``n_steps - 1`` inner times of ``n_steps`` equal steps from ``e1.t`` to ``e2.t``; with a
    multiple of 3 the bounds' times (5/3, 10/3) are among them."""
    return np.linspace(E1.t, E2.t, int(n_steps) + 1)[1:-1]


def plot_fig2(out: Path, times: Optional[Sequence[float]] = None,
              regions: Optional[dict[str, list[np.ndarray]]] = None) -> Path:
    """``out``: the three panels of 002 Fig. 2 as slices of the feasible region in ``(t, x, v)``
    (blue) at ``times``, the bounds (red squares) and the events (black dots); ``regions``:
    ``toy_regions(times)`` if already computed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    times = default_times() if times is None else np.asarray(times, dtype=float)
    regions = toy_regions(times) if regions is None else regions
    fig = plt.figure(figsize=(12, 4.2))
    for k, (name, polys) in enumerate(regions.items()):
        ax = fig.add_subplot(1, 3, k + 1, projection="3d")
        slices = [np.column_stack([np.full(len(p), t), p]) for t, p in zip(times, polys) if len(p) >= 3]
        ax.add_collection3d(Poly3DCollection(slices, facecolor=(0.2, 0.45, 0.85, 0.35),
                                             edgecolor=(0.1, 0.3, 0.7, 0.8), linewidths=0.4))
        for b in PAPER_CASES[name]:
            sq = np.column_stack([np.full(4, b.t), b.polygon()])
            ax.add_collection3d(Poly3DCollection([sq], facecolor=(1, 0, 0, 0.08), edgecolor="red", linewidths=1.5))
        for e in (E1, E2):
            ax.scatter([e.t], [e.x[0]], [e.v[0]], color="black", s=18, depthshade=False)
        vol = sum(area(p) for p in polys) * (times[1] - times[0])
        ax.set(xlim=(0, 5), ylim=(-3.5, 3.5), zlim=(-3, 3), xlabel="t (s)", ylabel="x (m)", zlabel="v (m/s)")
        ax.set_title(f"{name}: volume {vol:.2f} m²", fontsize=9)
        ax.set_proj_type("ortho")
        ax.view_init(elev=24, azim=-65)
        ax.set_box_aspect(None, zoom=0.85)
    fig.suptitle("002 Fig. 2: feasible regions of a mass point, |a| ≤ 2 m/s², e1 = (0, 0, 0), e2 = (0, 0, 5)",
                 fontsize=10)
    fig.subplots_adjust(left=0.0, right=0.97, bottom=0.02, top=0.9, wspace=0.05)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return out


@one_line_errors
def main(argv: Optional[Sequence[str]] = None) -> None:
    ap = parser(PROG, "002 Fig. 2: the toy problem's feasible regions (fig2_toy.png) and their volumes")
    ap.add_argument("--out", default=".", help="folder for fig2_toy.png (default: the current one)")
    args = ap.parse_args(argv)
    out = writable_folder(args.out, "--out")
    times = default_times()
    regions = toy_regions(times)
    path = plot_fig2(out / "fig2_toy.png", times, regions)
    for name, polys in regions.items():
        vol = sum(area(p) for p in polys) * (times[1] - times[0])
        at_t1 = area(polys[int(np.argmin(np.abs(times - B1.t)))])
        print(f"{name:14s} volume {vol:6.2f}  area at T1 {at_t1:5.2f} (b1's box: 4.00)")
    print(path)


if __name__ == "__main__":
    main()
