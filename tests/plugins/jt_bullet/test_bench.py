"""``jt_bullet.bench`` end to end on a tiny budget (speed is measured by it, not here)."""

from __future__ import annotations

import math


def test_time_spd_rows_and_summary():
    from jt_bullet.bench import BACKENDS, format_table, summarize, time_spd

    rows = time_spd(["humanoid", "snake195"], backends=BACKENDS, n_samples=3, seed=0)
    assert len(rows) == 2 * len(BACKENDS)
    keys = {"model", "dof", "depth", "backend", "solve_us_median", "step_us_median"}
    assert all(set(r) == keys for r in rows)
    by = {(r["model"], r["backend"]): r for r in rows}
    assert by[("humanoid", "maba")]["dof"] == 34 and by[("snake195", "maba")]["depth"] == 195
    assert math.isnan(by[("humanoid", "bullet")]["solve_us_median"])  # inside PyBullet's step
    assert by[("humanoid", "bullet")]["step_us_median"] > 0
    assert math.isnan(by[("snake195", "maba")]["step_us_median"])  # beyond PyBullet's API
    assert all(by[("snake195", b)]["solve_us_median"] > 0 for b in ("maba", "df", "sf", "pcg"))
    s = summarize(rows)
    assert s["df_over_maba_solve_195"] > 0 and math.isnan(s["maba_solve_growth_36_to_195"])
    assert "humanoid" in format_table(rows)


def test_the_servo_motors_are_timed_beside_stable_pd_on_request():
    """``servo`` (spd=servo's constraint motors) is opt-in: no solve time, a positive step time."""
    from jt_bullet.bench import BACKENDS, time_spd

    assert "servo" not in BACKENDS
    rows = {r["backend"]: r for r in time_spd(["humanoid"], backends=("df", "servo"), n_samples=3, seed=0)}
    assert math.isnan(rows["servo"]["solve_us_median"]) and rows["servo"]["step_us_median"] > 0
    assert rows["df"]["solve_us_median"] > 0


def test_check_agreement_reports_tiny_differences():
    from jt_bullet.bench import check_agreement

    assert check_agreement(["humanoid", "snake36"], n_states=2, seed=1) < 1e-8
