"""The standing-jump task end to end: real PyBullet jumps, real HDF5 and PNG files."""

from __future__ import annotations

import math

import numpy as np
import pytest
from omegaconf import OmegaConf

from jt_tasks.standing_jump import StandingJumpTask
from jt_tasks.standing_jump.objectives import effort
from toolkit.interfaces import EvalContext, Evaluation
from toolkit.store import h5

SUPERNATURAL = {"takeoff_gravity": -5.0, "assist_time": 0.5}
FALLS = {"takeoff_back": 1.2, "takeoff_hip": 1.5, "rise_hip": 2.2, "fall_back": 1.2}  # dives forward


def make_task(**overrides) -> StandingJumpTask:
    cfg = OmegaConf.create({"task": {"name": "standing_jump", "filmstrip_width": 48, "filmstrip_height": 72,
                                     **overrides}})
    return StandingJumpTask(cfg)


@pytest.fixture(scope="module")
def task() -> StandingJumpTask:
    return make_task()


@pytest.fixture(scope="module")
def runs(task, tmp_path_factory) -> dict[str, Evaluation]:
    """The seed controller, the seed with a gravity assist, and a diving controller."""
    sp = task.problem().space
    seed = sp.to_dict(sp.defaults())
    out = {}
    for i, (name, point) in enumerate((("seed", seed), ("assist", {**seed, **SUPERNATURAL}),
                                       ("falls", {**seed, **FALLS}))):
        ev = task.evaluate(point, EvalContext(index=i, seed=0, workdir=tmp_path_factory.mktemp(name)))
        ev.point = point
        out[name] = ev
    return out


def test_problem_is_the_papers(task):
    pr = task.problem()
    assert pr.space.dim == 34
    assert pr.n_objectives == 2 and tuple(pr.objective_names) == ("neg_height", "effort")
    ref = pr.reference_point
    assert ref[0] == pytest.approx(-1.4907, abs=1e-3)  # standing head height: no jump, no volume
    assert ref[1] > 15


def test_the_seed_controller_jumps_and_lands(runs, task):
    ev = runs["seed"]
    assert not ev.failed, ev.reason
    m = ev.metrics
    assert m["success"] == 1.0
    assert 1.55 < m["height"] < 2.6  # head apex above its standing 1.49 m
    assert m["flight_time"] > 0.15
    assert abs(m["landing_x"]) <= task.params.landing_tolerance
    assert m["liftoff_velocity"] > 1.0


def test_natural_jump_uses_exactly_zero_external_force(runs):
    m = runs["seed"].metrics
    assert m["external_energy"] == 0.0
    assert m["takeoff_gravity"] == -9.8 and m["force_application_time"] == 0.0
    assert m["natural"] == 1.0


def test_objectives_follow_the_equations(runs, task):
    for name in ("seed", "assist"):
        ev = runs[name]
        m = ev.metrics
        assert all(math.isfinite(v) for v in ev.objectives)
        if not ev.failed:
            assert ev.objectives[0] == pytest.approx(-m["height"])
            assert ev.objectives[1] == pytest.approx(math.log(m["internal_energy"] + 5000.0 * m["external_energy"]))
            assert ev.objectives[1] == pytest.approx(effort(m["internal_energy"], m["external_energy"]))
            assert np.all(np.asarray(ev.objectives) < np.asarray(task.reference_point()))


def test_gravity_assist_costs_external_effort_and_lifts_higher(runs):
    nat, sup = runs["seed"].metrics, runs["assist"].metrics
    assert sup["natural"] == 0.0
    assert sup["takeoff_gravity"] == -5.0 and sup["force_application_time"] == 0.5
    # F = m (g + 9.8) ramping to 0 over T: sum F^2 dt = (m a)^2 T / 3
    assert sup["external_energy"] == pytest.approx((80.0 * 4.8) ** 2 * 0.5 / 3, rel=0.02)
    assert sup["com_height"] > nat["com_height"] + 0.05
    assert sup["effort"] > nat["effort"]


def test_a_diving_controller_fails_with_a_reason_and_penalty(runs, task):
    ev = runs["falls"]
    assert ev.failed and ev.reason in ("fall", "not_upright", "landing_outside_box", "no_recovery")
    assert ev.metrics["success"] == 0.0
    assert all(o >= 0.5 * task.params.f_p for o in ev.objectives)


def test_same_parameters_same_result(runs, task, tmp_path):
    again = task.evaluate(runs["seed"].point, EvalContext(index=0, seed=1, workdir=tmp_path))
    assert again.metrics == runs["seed"].metrics
    assert list(again.objectives) == list(runs["seed"].objectives)
    data = h5.read(tmp_path / "jump.h5")
    assert set(data["trajectory"]) >= {"time", "com_x", "com_z", "angular_momentum"}
    assert "rise" in list(data["events"]["phase"])


def test_summarize_writes_the_front_table_and_pictures(runs, task, tmp_path):
    evs = [runs["seed"], runs["assist"], runs["falls"]]
    out = task.summarize(evs, tmp_path)
    data = h5.read(tmp_path / "front.h5")
    s = data["samples"]
    for col in ("internal_energy", "takeoff_gravity", "force_application_time", "height", "non_dominated"):
        assert len(s[col]) == 3, col
    assert list(s["failed"]) == [False, not runs["assist"].metrics["success"], True]
    assert not s["non_dominated"][2]  # a failure is never on the front
    assert s["takeoff_gravity"][0] == -9.8 and s["force_application_time"][1] == 0.5
    assert data["front"]["height"].tolist() == sorted(data["front"]["height"].tolist())
    assert out["n_front"] == float(np.sum(s["non_dominated"]))
    assert out["max_natural_height"] == pytest.approx(runs["seed"].metrics["height"])
    assert out["hypervolume"] > 0.0
    steps, curve = zip(*out["hypervolume_curve"])  # hypervolume against simulations (004 §5)
    assert steps == (1, 2, 3) and curve[-1] == pytest.approx(out["hypervolume"])
    assert list(data["hypervolume_curve"]) == pytest.approx(list(curve))
    assert (tmp_path / "front.png").stat().st_size > 1000
    assert (tmp_path / "filmstrip_lowest_natural.png").stat().st_size > 1000
    assert (tmp_path / "filmstrip_highest_natural.png").exists()
    import imageio.v3 as iio

    gif = iio.imread(tmp_path / "jump_lowest_natural.gif")  # the same jump, moving (default 160 px: shown at 320)
    assert gif.ndim == 4 and gif.shape[0] > 5 and gif.shape[2] == 48  # test-sized frames (< 96 px) stay as rendered
    if runs["assist"].metrics["success"]:
        assert (tmp_path / "filmstrip_highest_supernatural.png").exists()


def test_summarize_of_nothing(task, tmp_path):
    out = make_task(filmstrips=False).summarize([], tmp_path)
    assert out["n_front"] == 0.0 and out["hypervolume"] == 0.0
    assert math.isnan(out["max_natural_height"])
    assert (tmp_path / "front.h5").exists()
