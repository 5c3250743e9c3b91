"""task=spd_tracking: reference motions, tracking error vs time step, artifacts, a real run."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from toolkit.errors import JtError

from toolkit.interfaces import EvalContext

TRACK = {"sim": {"name": "bullet", "torque_limits": False, "contacts": False,
                 "root_servo": {"kp": 20000.0, "kd": 2000.0}},            # 001 §2.4.1
         "character": {"name": "humanoid", "kp": 75000.0, "kd": 4000.0},
         "spd": {"name": "maba"}}


def loaded(name: str):
    """A character in its own client (the caller disconnects ``ch.client``)."""
    import pybullet as pb

    from jt_bullet.simulator import BulletSimulator

    return BulletSimulator.load_character(name, pb.connect(pb.DIRECT))


@pytest.fixture(scope="module")
def run_ref():
    import pybullet as pb

    from jt_tasks.spd_tracking.motions import make_reference

    ch = loaded("humanoid")
    ref = make_reference(ch, "run")
    pb.disconnect(ch.client)
    return ref


def test_clip_velocities_are_the_derivative_and_skip_the_seam(run_ref):
    from toolkit.motion import rotations as rot

    ref, h = run_ref, 1e-3
    t = np.array([0.11, 0.37, 0.52])  # inside frame segments
    v = ref.velocities(t)
    q0, q1 = ref.poses(t), ref.poses(t + h)
    np.testing.assert_allclose(v[:, :3], (q1[:, :3] - q0[:, :3]) / h, rtol=1e-6, atol=1e-6)
    w = rot.quat_to_expmap(rot.quat_multiply(q1[:, 3:7], rot.quat_conjugate(q0[:, 3:7]))) / h
    np.testing.assert_allclose(v[:, 3:6], w, atol=1e-6)
    # at a cycle's start and end the difference is one-sided: no jump from the data's seam
    T = ref.duration
    seam = ref.velocities(np.array([0.0, T, 2 * T]))
    inside = ref.velocities(np.linspace(0.01, T - 0.01, 50))
    assert np.abs(seam).max() < 1.5 * np.abs(inside).max()


def test_laikago_mocap_is_turned_into_the_y_up_world():
    import pybullet as pb

    from jt_tasks.spd_tracking.motions import make_reference
    from jt_bullet.body import BulletBody

    ch = loaded("laikago")
    try:
        ref = make_reference(ch, "auto")
        io = BulletBody(ch.client, ch.body_id, ch.model())
        toes = [12, 13, 14, 15]
        lowest = []
        for q in ref.poses(np.linspace(0.0, ref.duration, 6)):
            io.reset(q, np.zeros(ch.n_dof))
            ys = [pb.getLinkState(ch.body_id, k, computeForwardKinematics=True,
                                  physicsClientId=ch.client)[4][1] for k in toes]
            lowest.append(min(ys))
        assert np.all(np.abs(lowest) < 0.05)  # a toe on the ground (y = 0) in every pose
        end = ref.pose(ref.duration)
        assert end[0] > 0.2 and abs(end[2]) < 0.05  # walks along +x
    finally:
        pb.disconnect(ch.client)


def test_snake_wave_follows_its_formula():
    import pybullet as pb

    from jt_tasks.spd_tracking.motions import WaveParams, make_reference
    from toolkit.motion import rotations as rot

    ch = loaded("snake36")
    pb.disconnect(ch.client)
    p = WaveParams(amplitude=0.3, frequency=1.0, wavelength=10.0, speed=0.2, height=0.02)
    ref = make_reference(ch, "auto", p)
    q = ref.pose(0.4)
    assert np.allclose(q[:3], [-0.08, 0.02, 0.0]) and np.allclose(q[3:7], [0, 0, 0, 1])
    quats = q[7:].reshape(10, 4)
    angles = rot.quat_to_expmap(quats)
    expected = 0.3 * np.sin(2 * np.pi * 0.4 - 2 * np.pi * np.arange(1, 11) / 10.0)
    np.testing.assert_allclose(angles[:, 1], expected, atol=1e-12)  # about the vertical (y)
    assert np.allclose(angles[:, [0, 2]], 0.0)


def test_unknown_motion_lists_the_choices():
    import pybullet as pb

    from jt_tasks.spd_tracking.motions import make_reference

    ch = loaded("humanoid")
    pb.disconnect(ch.client)
    with pytest.raises(JtError, match="backflip"):
        make_reference(ch, "moonwalk")
    with pytest.raises(JtError, match="slither"):
        make_reference(ch, "slither")


def test_error_is_small_at_1_600_and_grows_with_the_time_step(run_ref):
    from jt_tasks.spd_tracking.tracking import track

    fine = track(TRACK, run_ref, 600.0, 0.5)
    coarse = track(TRACK, run_ref, 30.0, 0.5)
    assert not fine.diverged and not coarse.diverged
    assert fine.n_steps == 300 and coarse.n_steps == 15
    assert np.nanmean(fine.error) < 0.03 and np.nanmax(fine.error) < 0.06  # a few cm
    assert np.nanmean(coarse.error) > np.nanmean(fine.error)
    assert fine.fps > 0 and 0.0 < fine.spd_share < 1.0


def test_df_and_maba_track_identically(run_ref):
    from jt_tasks.spd_tracking.tracking import track

    a = track(TRACK, run_ref, 120.0, 0.25)
    b = track({**TRACK, "spd": {"name": "df"}}, run_ref, 120.0, 0.25)
    np.testing.assert_allclose(a.error, b.error, atol=1e-7)


def test_divergence_is_recorded_not_raised(run_ref):
    from jt_tasks.spd_tracking.tracking import track

    wild = {**TRACK, "character": {"name": "humanoid", "kp": 1e12, "kd": -1e6}}
    res = track(wild, run_ref, 30.0, 0.5)
    assert res.diverged and res.reason
    assert res.n_steps < 15 and np.all(np.isnan(res.error[res.n_steps:]))


def _task(tmp: Path, **task):
    from omegaconf import OmegaConf

    from jt_tasks.spd_tracking.task import SPDTrackingTask

    cfg = OmegaConf.create({"task": {"name": "spd_tracking", "rates_hz": [30.0, 600.0],
                                     "duration": 0.2, "fps_duration": 0.5, **task},
                            "sim": {"name": "bullet"}, "character": {"name": "humanoid"},
                            "spd": {"name": "maba"}})
    return SPDTrackingTask(cfg)


def test_evaluation_writes_the_hdf5_plot_and_metrics(tmp_path):
    from toolkit.store import h5

    task = _task(tmp_path, render=True, render_rate_hz=30.0, render_width=48, render_height=36)
    ev = task.evaluate({}, EvalContext(index=0, seed=0, workdir=tmp_path))
    assert not ev.failed
    for key in SPD_KEYS:
        assert key in ev.metrics
    assert ev.metrics["fps"] > 0 and 0 < ev.metrics["spd_share_pct"] < 100
    assert ev.metrics["n_diverged"] == 0.0 and ev.metrics["dof"] == 34.0
    d = h5.read(tmp_path / "spd_tracking.h5")
    np.testing.assert_allclose(d["rates_hz"], [30.0, 600.0])
    run = d["runs"]["dt600"]
    assert run["time"].shape == run["error"].shape == (120,) and run["ee_sim"].shape == (120, 3)
    assert math.isclose(float(np.mean(run["error"])), ev.metrics["err_mean_dt600"])
    assert d["model"]["depth"] == 13 and d["fps_rate_hz"] == 30.0
    for name in ("tracking_error.png", "filmstrip.png", "tracking.gif"):
        assert (tmp_path / name).stat().st_size > 500
    assert task.problem().space.params == ()


SPD_KEYS = ("fps", "spd_share_pct", "err_mean_dt30", "err_max_dt30", "err_mean_dt600",
            "diverged_dt30", "n_diverged")


def _prefix() -> str:
    """``+`` while conf/config.yaml has no sim/character/spd defaults (the lead adds them)."""
    from toolkit.config import conf_dir

    return "" if "- sim:" in (conf_dir() / "config.yaml").read_text() else "+"


def test_smoke_run_through_the_runner(tmp_path):
    from toolkit.config import compose
    from toolkit.execution.runner import run
    from toolkit.store.tracking import Store

    p = _prefix()
    cfg = compose(["task=spd_tracking", f"{p}sim=bullet", f"{p}character=humanoid",
                   f"{p}spd=maba", "experiment=smoke", f"store={tmp_path / 'store'}"])
    res = run(cfg)
    store = Store(tmp_path / "store")
    assert store.get_run(res.run_id).info.status == "FINISHED"
    assert (store.artifact_dir(res.run_id) / "spd_tracking.h5").is_file()
    assert res.metrics["n_diverged"] == 0.0 and res.metrics["err_mean_dt600"] < 0.05
