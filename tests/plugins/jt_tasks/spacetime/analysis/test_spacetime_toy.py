"""002 §3.1's toy (Fig. 2, eq 1): feasible regions of a mass point with |a| <= 2 m/s², in closed form."""

from __future__ import annotations

import numpy as np
import pytest

from jt_tasks.spacetime.analysis import toy


CHORD = 2e-3
"""m: polygons with 64 vertices per bang-bang arc lie within this of the exact sets (measured:
5e-4 between two cases' regions; 3e-5 with 256), so one case's region may poke this far out of
another's."""


def depth(points: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Per point: its distance inside the counter-clockwise convex polygon ``poly`` (< 0: outside)."""
    a, b = poly, np.roll(poly, -1, axis=0)
    d = b - a
    n = np.linalg.norm(d, axis=1)
    a, d, n = a[n > 1e-12], d[n > 1e-12], n[n > 1e-12]  # clipping leaves repeated vertices
    side = d[None, :, 0] * (points[:, None, 1] - a[None, :, 1]) - d[None, :, 1] * (points[:, None, 0] - a[None, :, 0])
    return (side / n[None, :]).min(axis=1)


def inside(points: np.ndarray, poly: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """Per point: inside ``poly`` within ``tol``."""
    return depth(points, poly) >= -tol


@pytest.mark.parametrize("x0,v0,t", [(0.0, 0.0, 1.0), (0.3, -0.7, 2.2)])
def test_from_a_point_the_reach_is_x0_plus_v0_t_plus_minus_a_t2_over_2(x0, v0, t):
    start = toy.Box(0.0, (x0, x0), (v0, v0))
    f = toy.forward(t, start, ())
    a = toy.A_MAX
    assert f[:, 0].min() == pytest.approx(x0 + v0 * t - a * t * t / 2, abs=1e-12)
    assert f[:, 0].max() == pytest.approx(x0 + v0 * t + a * t * t / 2, abs=1e-12)
    assert (f[:, 1].min(), f[:, 1].max()) == (pytest.approx(v0 - a * t), pytest.approx(v0 + a * t))
    # the set reachable from rest has area 2/3 a² t³ (between the two bang-bang parabolas)
    assert toy.area(toy.reach_from_rest(t, a, n_arc=2000)) == pytest.approx(2 / 3 * a * a * t ** 3, rel=1e-5)


def test_bang_bang_trajectories_stay_inside_the_forward_set_and_one_switch_ones_reach_its_edge():
    rng = np.random.default_rng(0)
    n, steps, t, a = 400, 300, 1.5, toy.A_MAX
    dt = t / steps

    def ends(acc: np.ndarray) -> np.ndarray:  # exact for piecewise-constant acceleration from rest
        v = np.cumsum(acc * dt, axis=1)
        return np.column_stack([np.sum((v - acc * dt / 2) * dt, axis=1), v[:, -1]])

    wild = rng.choice([-a, a], size=(n, steps)) * rng.uniform(0, 1, size=(n, steps))
    switch = rng.integers(0, steps + 1, size=n)
    sign = rng.choice([-1.0, 1.0], size=(n, 1))
    one = sign * a * np.where(np.arange(steps)[None, :] < switch[:, None], 1.0, -1.0)
    f = toy.forward(t, toy.E1, (), n_arc=64)
    assert inside(ends(wild), f, tol=1e-3).all()
    assert np.abs(depth(ends(one), f)).max() < 1e-3  # the boundary is the one-switch arcs


def test_without_bounds_the_midpoint_x_range_is_the_accelerate_brake_return_extreme():
    # from rest at 0 back to rest at 0 in 5 s: +a 1.25 s, -a 2.5 s, +a 1.25 s peaks at a 1.25² at t = 2.5
    p = toy.feasible(2.5, toy.E1, toy.E2, (), n_arc=400)
    assert p[:, 0].max() == pytest.approx(toy.A_MAX * 1.25 ** 2, abs=1e-4)
    assert p[:, 0].min() == pytest.approx(-toy.A_MAX * 1.25 ** 2, abs=1e-4)


def test_bounds_never_enlarge_and_in_the_papers_setting_strictly_shrink_the_region():
    times = toy.default_times()
    regions = toy.toy_regions(times)
    none, one, two = (regions[k] for k in toy.PAPER_CASES)
    dt = times[1] - times[0]
    vols = [sum(toy.area(p) for p in r) * dt for r in (none, one, two)]
    for small, big in ((one, none), (two, one)):
        for p, q in zip(small, big):
            assert toy.area(p) <= toy.area(q) + 1e-9
            assert len(p) == 0 or inside(p, q, tol=CHORD).all()
    assert vols[0] > vols[1] > vols[2] > 0  # every added bound shrinks it (002 §3.1)
    assert vols[2] < 0.2 * vols[0]
    k1 = int(np.argmin(np.abs(times - toy.B1.t)))
    at_b1 = two[k1]
    assert inside(at_b1, toy.B1.polygon(), tol=1e-9).all()
    assert toy.area(at_b1) < 0.3 * toy.area(toy.B1.polygon())  # "much thinner than the bounds" (Fig. 2)
    # the +b1, b2 case is mirror-symmetric: (x, v, t) -> (-x, v, 5 - t) maps b1 onto b2
    assert [toy.area(p) for p in two] == pytest.approx([toy.area(p) for p in two[::-1]], rel=1e-6)


def test_more_bounds_anywhere_never_enlarge_it():
    rng = np.random.default_rng(1)
    times = np.array([0.7, 1.9, 2.5, 3.6, 4.4])
    for _ in range(4):
        bt = float(rng.uniform(0.5, 4.5))
        cx, cv = rng.uniform(-2, 2), rng.uniform(-1.5, 1.5)
        extra = toy.Box(bt, (cx - 1.0, cx + 1.0), (cv - 1.0, cv + 1.0))
        for t in times:
            base = toy.feasible(t, bounds=(toy.B1,))
            more = toy.feasible(t, bounds=(toy.B1, extra))
            assert toy.area(more) <= toy.area(base) + 1e-9
            assert len(more) == 0 or inside(more, base, tol=CHORD).all()


def test_an_unreachable_bound_leaves_nothing():
    far = toy.Box(1.0, (5.0, 6.0), (-1.0, 1.0))  # x >= 5 in 1 s needs a >= 10 m/s²
    assert len(toy.feasible(2.0, bounds=(far,))) == 0 and len(toy.feasible(0.5, bounds=(far,))) == 0


def test_the_command_writes_fig2_toy_png(tmp_path, capsys):
    toy.main(["--out", str(tmp_path)])
    out = tmp_path / "fig2_toy.png"
    assert out.stat().st_size > 20_000
    text = capsys.readouterr().out
    assert "+ b1, b2" in text and str(out) in text


def test_an_out_folder_that_cannot_be_written_is_one_line_before_the_regions(tmp_path, capsys):
    (tmp_path / "file").write_text("")
    with pytest.raises(SystemExit) as e:
        toy.main(["--out", str(tmp_path / "file")])
    out, err = capsys.readouterr()
    assert e.value.code == 2 and out == "" and err.startswith(f"jt: --out={tmp_path / 'file'}: cannot write there")
    assert len(err.strip().splitlines()) == 1
