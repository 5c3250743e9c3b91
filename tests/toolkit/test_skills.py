"""Shipped skills (toolkit/skills.py, ``jt play``): found through the tasks' ``skills`` packages,
listed, their manifests read and checked, and every mistake one line with exit status 2. (The
replays themselves: tests/plugins/jt_tasks/jumping/test_skills_fosbury.py.)"""

from __future__ import annotations

import shutil

import pytest
import yaml

from tests.conftest import one_line_error, run_jt
from toolkit import skills
from toolkit.errors import JtError


@pytest.fixture()
def fosbury_copy(tmp_path):
    """A copy of the shipped fosbury skill's folder, to break."""
    dst = tmp_path / "fosbury"
    shutil.copytree(skills.find("fosbury").folder, dst)
    return dst


def test_the_shipped_skills_are_found_through_the_tasks():
    assert "jt_tasks.jumping.skills" in skills.packages()
    found, broken = skills.scan()
    assert not broken, broken
    fos = skills.find("fosbury")
    assert [s.name for s in found].count("fosbury") == 1  # three jumping tasks, one package, listed once
    assert fos.task == "highjump" and fos.policy.is_file() and (fos.folder / "prior.h5").is_file()
    assert fos.measure["cleared"] is True and fos.measure["bar_m"] == 1.0
    assert abs(fos.measure["strategy_angle_rad"] - 1.924) < 1e-9
    assert fos.env_attrs["bar_height"] == 1.0 and fos.point == {"alpha": -0.05, "omega_x": -3.0, "omega_z": 1.0,
                                                                "v_z": -2.4}
    prov = fos.provenance
    assert prov["run_id"] == "616fc42dedbd4dd5b112e47224cf29ff" and prov["samples"] == 667648
    assert fos.command.startswith("jt run task=highjump ") and "store=" not in fos.command
    assert fos.policy.stat().st_size < 4e6  # slim: no value net, no optimiser states


def test_overrides_naming_a_file_of_the_folder_point_at_it():
    fos = skills.find("fosbury")
    assert "action.prior=prior.h5" in fos.overrides
    resolved = fos.resolved_overrides()
    assert f"action.prior={fos.folder / 'prior.h5'}" in resolved
    assert [o for o in resolved if not o.startswith("action.prior=")] == \
        [o for o in fos.overrides if not o.startswith("action.prior=")]


def test_listing_names_task_measure_and_description():
    lines = skills.listing()
    line = next(ln for ln in lines if ln.startswith("fosbury "))
    assert "task=highjump" in line and "cleared=true bar_m=1.0 strategy_angle_rad=1.924" in line
    assert "Fosbury flop" in line


def test_unknown_name_lists_the_shipped_ones():
    with pytest.raises(JtError, match=r"unknown skill 'nope'; shipped skills: .*fosbury"):
        skills.find("nope")


def test_measure_differences():
    doc = {"cleared": True, "bar_m": 1.0, "strategy_angle_rad": 1.924}
    assert skills.differences({"cleared": True, "bar_m": 1.0, "strategy_angle_rad": 1.95}, doc) == []
    assert skills.differences({"cleared": False, "bar_m": 1.0, "strategy_angle_rad": 2.2}, doc) == \
        ["cleared=False (documented True)", "strategy_angle_rad=2.2 (documented 1.924)"]
    assert skills.differences({"cleared": True, "bar_m": 1.0, "strategy_angle_rad": None}, doc)


def _write(folder, text):
    (folder / "manifest.yaml").write_text(text)


def _edit(**changes):
    def edit(folder):
        data = yaml.safe_load((folder / "manifest.yaml").read_text())
        data.update(changes)
        data = {k: v for k, v in data.items() if v is not None}
        _write(folder, yaml.safe_dump(data))
    return edit


@pytest.mark.parametrize("change, message", [
    (lambda f: (f / "manifest.yaml").unlink(), "no manifest.yaml there"),
    (lambda f: _write(f, "name: [unclosed"), "not readable YAML"),
    (lambda f: _write(f, "- a list"), "is not a mapping"),
    (_edit(overrides=None), "lacks overrides"),
    (_edit(overrides="task=highjump"), "overrides must be a list"),
    (_edit(point=[1, 2]), "point must be a mapping"),
    (_edit(name="../up"), "must be letters, digits"),
    (_edit(seed="x"), "seed must be an integer"),
    (lambda f: (f / "policy.h5").unlink(), "no policy.h5 beside"),
])
def test_a_broken_manifest_is_one_line(fosbury_copy, change, message):
    change(fosbury_copy)
    with pytest.raises(JtError) as e:
        skills.load_manifest(fosbury_copy)
    assert message in str(e.value) and len(str(e.value).splitlines()) == 1
    assert str(e.value).startswith(f"skill {fosbury_copy}")


def test_a_manifest_round_trips(fosbury_copy):
    skill = skills.load_manifest(fosbury_copy)
    skill.description = "changed"
    skills.write_manifest(skill)
    again = skills.load_manifest(fosbury_copy)
    assert again.description == "changed"
    assert (again.overrides, again.point, again.env_attrs, again.measure, again.provenance) == \
        (skill.overrides, skill.point, skill.env_attrs, skill.measure, skill.provenance)


def test_numpy_values_are_written_as_plain_yaml(fosbury_copy):
    """A run's environment attributes may be arrays (a spacetime run's start-phase weights): the
    manifest holds them as lists and numbers, not as a YAML error."""
    import numpy as np

    skill = skills.load_manifest(fosbury_copy)
    skill.env_attrs = {**skill.env_attrs, "start_sampling": {"probs": np.array([0.25, 0.75])},
                       "level": np.int64(3), "on": np.bool_(True)}
    skills.write_manifest(skill)
    again = skills.load_manifest(fosbury_copy)
    assert again.env_attrs["start_sampling"] == {"probs": [0.25, 0.75]}
    assert again.env_attrs["level"] == 3 and again.env_attrs["on"] is True


def test_jt_play_lists_the_skills():
    p = run_jt("play")
    assert p.returncode == 0, p.stderr
    lines = p.stdout.splitlines()
    assert lines[0].startswith("jt play NAME: replay a shipped skill")
    assert any(ln.split()[:2] == ["fosbury", "task=highjump"] for ln in lines[1:])
    assert any(ln.split()[:2] == ["walk", "task=spacetime"] for ln in lines[1:])


def test_jt_play_mistakes_are_one_line(tmp_path):
    assert "unknown skill 'nope'; shipped skills: " in one_line_error(run_jt("play", "nope"))
    assert "renders at least 320x240 px" in one_line_error(run_jt("play", "fosbury", "--width", "100"))
    assert "--seconds 0.0: must be a number of seconds > 0" in one_line_error(run_jt("play", "fosbury", "--seconds", "0"))
    err = one_line_error(run_jt("play", "0123456789abcdef0123456789abcdef", "--store", str(tmp_path / "none")))
    assert err.startswith("jt: jt play 0123456789abcdef0123456789abcdef: no such run")
    assert "no ppo.h5 there" in one_line_error(run_jt("play", str(tmp_path)))
    assert "give the run's id" in one_line_error(run_jt("play", "--ship", str(tmp_path), "x"))
    assert "give the skill's name" in one_line_error(run_jt("play", "--ship", "0123456789abcdef0123456789abcdef"))
