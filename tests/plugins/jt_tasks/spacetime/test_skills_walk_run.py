"""The shipped ``walk`` and ``run`` skills replayed (``jt play walk``): real PyBullet, the slim
policies from the repository. Each was trained by ``experiment=laptop`` to Table 1's measure (002:
20 s from every start phase); the default suite holds the first 5 s from phase 0, ``-m slow`` the
whole 20 s from the four start phases of the training's evaluation."""

from __future__ import annotations

import pytest

from toolkit import play, play_targets, skills

SHIPPED = ("walk",)  # the run: when its experiment=laptop training is shipped


@pytest.fixture(scope="module", params=SHIPPED)
def skill(request):
    return skills.find(request.param)


def test_the_manifest_documents_table_1s_measure(skill):
    assert skill.task == "spacetime" and ("task.clip=run" in skill.overrides) == (skill.name == "run")
    assert skill.measure["survived"] is True and skill.measure["survival_s"] == pytest.approx(20.0, abs=0.05)
    assert skill.measure["start_phase"] == 0.0
    prov = skill.provenance
    assert prov["samples"] > 1_000_000 and len(prov["commit"]) == 40 and len(prov["run_id"]) == 32
    assert prov["command"].startswith("jt run task=spacetime experiment=laptop")
    assert prov["metrics"]["survival_min_s"] == pytest.approx(20.0, abs=0.05)  # every start phase, at the run's end


def test_the_first_five_seconds_from_phase_0(skill, tmp_path):
    done = play.replay(play_targets.from_skill(skill), tmp_path, seconds=5.0)
    assert done.capped and done.measure["survival_s"] == pytest.approx(5.0, abs=0.05)
    assert done.line.startswith(f"{skill.name}: still up at 5.0") and "from clip phase 0.00" in done.line
    assert done.files[0].name == f"{skill.name}.gif" and done.size == (320, 240)
    if play.mp4_writer():  # the README's install has imageio-ffmpeg (.[video])
        assert [f.name for f in done.files] == [f"{skill.name}.gif", f"{skill.name}.mp4"]


@pytest.mark.slow
@pytest.mark.parametrize("phase", ["0", "0.25", "0.5", "0.75"])
def test_twenty_seconds_from_every_start_phase(skill, phase):
    done = play.replay(play_targets.from_skill(skill), None, start=phase)
    assert done.measure["survived"] is True, done.line
    assert done.measure["survival_s"] == pytest.approx(20.0, abs=0.05)
