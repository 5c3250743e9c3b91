"""The shipped ``fosbury`` skill replayed (``jt play fosbury``: toolkit/play.py, play_targets.py,
ship.py): real PyBullet, its slim policy and prior from the repository. The jump is ~0.6 s of
simulation; it clears the 1.00 m bar with the documented strategy feature. A run of a store replays
and ships the same way."""

from __future__ import annotations

import shutil

import imageio.v3 as iio
import numpy as np
import pytest
import yaml

from tests.conftest import run_jt
from toolkit import play, play_targets, skills
from toolkit.config import compose_skill
from toolkit.errors import JtError


@pytest.fixture(scope="module")
def fosbury():
    return skills.find("fosbury")


@pytest.fixture(scope="module")
def target(fosbury):
    return play_targets.from_skill(fosbury)


def test_fosbury_clears_its_bar_as_documented(target, fosbury, tmp_path):
    done = play.replay(target, tmp_path / "out")
    doc = fosbury.measure
    assert done.measure["cleared"] is True and doc["cleared"] is True
    assert done.measure["bar_m"] == doc["bar_m"] == 1.0
    assert abs(done.measure["strategy_angle_rad"] - doc["strategy_angle_rad"]) < 0.05
    assert "cleared the bar at 1.00 m; strategy feature angle 1.92" in done.line
    assert not done.capped and not any("differs" in n for n in done.notes)
    gif = tmp_path / "out" / "fosbury.gif"
    assert done.files[0] == gif and gif.is_file()
    frame = iio.imread(gif, index=0)
    assert frame.shape[1] >= 320 and frame.shape[0] >= 240 and done.size == (320, 240)
    assert done.frames == 19  # the take-off state and 18 control steps at 30 Hz


def test_seconds_cut_the_episode_and_start_is_refused(target, monkeypatch):
    from toolkit.render import window_requested

    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    done = play.replay(target, None, seconds=0.2, gui=True)
    assert done.capped and done.frames == 7 and not done.files
    if play.display():  # no display here (macOS and Windows always have one)
        assert done.notes == ["--gui: no display here (DISPLAY is unset); replayed headless"]
    assert not window_requested()
    assert done.measure["cleared"] is False and "[cut at --seconds 0.2]" in done.line
    with pytest.raises(JtError, match=r"--start=0.5: task=highjump replays its one start"):
        play.replay(target, None, start="0.5")


def test_a_skill_whose_policy_no_longer_fits_names_its_retraining(fosbury, tmp_path):
    folder = tmp_path / "fosbury"
    shutil.copytree(fosbury.folder, folder)
    data = yaml.safe_load((folder / "manifest.yaml").read_text())
    data["overrides"] = [o for o in data["overrides"] if not o.startswith("action.prior=")] + ["action=raw"]
    (folder / "manifest.yaml").write_text(yaml.safe_dump(data))
    p = run_jt("play", str(folder), "--out", str(tmp_path / "out"))
    assert p.returncode == 2, p.stderr[-500:]
    err = p.stderr.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert err.startswith("jt: skill 'fosbury' must be retrained for this jt (its policy takes 126 observations "
                          "and gives 45 actions")
    assert f"retrain it with: {fosbury.command}, then ship the run: jt play --ship RUN_ID fosbury" in err
    assert not (tmp_path / "out" / "fosbury.gif").exists()


@pytest.fixture(scope="module")
def trained_run(fosbury, tmp_path_factory):
    """A store holding a finished run as jt run leaves one: the fosbury policy as its ppo.h5 (whose
    env_attrs hold the curriculum's last bar, 1.02 m), its config, its search history (the final
    rollout reached 1.00 m), its command, commit and metrics."""
    from toolkit.config import to_yaml
    from toolkit.store import h5
    from toolkit.store.opening import open_store

    root = tmp_path_factory.mktemp("run")
    st = open_store(root / "store")
    overrides = [o for o in fosbury.overrides if not o.startswith("action.prior=")]
    rid = st.start_run("highjump", tags={"jt.command": "jt run " + " ".join(overrides) + f" store={st.root}",
                                         "jt.git_commit": "0" * 40, "jt.task": "highjump"})
    art = root / "art"
    art.mkdir()
    shutil.copyfile(fosbury.policy, art / "ppo.h5")
    (art / "config.yaml").write_text(to_yaml(compose_skill(fosbury)))
    point = fosbury.point
    h5.write(art / "search_history.h5", {"names": np.array(list(point), dtype="S"), "index": np.array([0]),
                                          "x": np.array([list(point.values())]),
                                          "metrics": {"bar_height_reached": np.array([1.0])}})
    st.log_artifacts(rid, art)
    with st.metrics(rid) as m:
        m.add_many({"samples": 667648.0, "train_wall_s": 1428.5, "bar_height_reached": 1.0})
    st.end_run(rid)
    return st, rid, art


def test_a_run_replays_at_the_bar_its_final_rollout_reached(trained_run, tmp_path):
    st, rid, art = trained_run
    target = play_targets.from_run(rid, str(st.root))
    assert target.label == f"run-{rid[:8]}" and target.task_name == "highjump"
    assert target.env_attrs["bar_height"] == 1.0  # the checkpoint says 1.02: the run's metrics win
    assert target.point == {"alpha": -0.05, "omega_x": -3.0, "omega_z": 1.0, "v_z": -2.4}
    bare = tmp_path / "bare"  # the files alone, no search history: the checkpoint's own attributes
    bare.mkdir()
    shutil.copyfile(art / "ppo.h5", bare / "ppo.h5")
    shutil.copyfile(art / "config.yaml", bare / "config.yaml")
    alone = play_targets.from_run(str(bare))
    assert alone.env_attrs["bar_height"] == 1.02 and alone.point == {} and alone.label == "highjump-bare"


def test_ship_makes_a_skill_from_a_run(trained_run, fosbury, tmp_path):
    st, rid, _ = trained_run
    from toolkit.ship import ship

    skill = ship(rid, "flop", str(st.root), tmp_path / "skills", "a copy")
    again = skills.load_manifest(tmp_path / "skills" / "flop")
    assert again.name == "flop" and again.description == "a copy" and again.task == "highjump"
    assert again.measure == skill.measure == fosbury.measure
    assert again.overrides[-1] == "action.prior=prior.h5" and "store=" not in " ".join(again.overrides)
    assert again.env_attrs == fosbury.env_attrs and again.point == fosbury.point
    assert again.provenance["run_id"] == rid and again.provenance["samples"] == 667648
    assert again.provenance["commit"] == "0" * 40 and "store=" not in again.provenance["command"]
    assert (again.folder / "prior.h5").read_bytes() == (fosbury.folder / "prior.h5").read_bytes()
    from toolkit.rl.checkpoint import load_attrs

    assert load_attrs(again.policy)["slim"]


def test_a_ship_that_fails_leaves_no_half_written_skill(trained_run, tmp_path, monkeypatch):
    """A replay that fails after the policy was written (here: interrupted) takes the new folder
    with it; a skill that was there before is left for the user."""
    import toolkit.ship as ship_module

    st, rid, _ = trained_run

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(ship_module, "replay", interrupted)
    with pytest.raises(KeyboardInterrupt):
        ship_module.ship(rid, "flop", str(st.root), tmp_path / "skills")
    assert not (tmp_path / "skills" / "flop").exists()
