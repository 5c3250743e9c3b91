"""``task.evaluate=NAME``: a shipped skill (``jt play`` lists them) measured by ``jt run`` and
recorded in the store like any run: its slim policy, in the environment its manifest composes
(its overrides under the command line's, its env attributes: the Fosbury flop's 1.00 m bar), no
sample collected. An unknown name lists the shipped ones; a setting that changes the skill's
environment is one line before a run opens. Real stores in temp dirs."""

from __future__ import annotations

import math

import pytest

from toolkit.errors import JtError


def _compose(tmp_path, *overrides):
    from toolkit.config import compose

    return compose([*overrides, f"store={tmp_path}"])


def test_the_fosbury_skill_is_measured_and_recorded_as_a_run(tmp_path):
    from toolkit import skills
    from toolkit.execution.runner import run
    from toolkit.rl.checkpoint import load_attrs

    skill = skills.find("fosbury")
    res = run(_compose(tmp_path, "task=highjump", "search=single", "task.evaluate=fosbury"))
    run_ = res.store.client.get_run(res.run_id)
    m = run_.data.metrics
    assert run_.info.status == "FINISHED"
    assert m["strategy_angle"] == pytest.approx(skill.measure["strategy_angle_rad"], abs=0.01)  # 1.924 rad
    assert m["bar_height_reached"] == pytest.approx(1.0) and m["bar_height_trained"] == pytest.approx(1.0)
    assert m["final_success"] == 1.0 and math.isnan(m["success_rate"])  # cleared; no training to have a rate
    assert m["samples"] == skill.provenance["samples"] and m["train_wall_s"] == 0.0  # nothing collected
    art = res.store.artifact_dir(res.run_id)
    assert (art / "motion.gif").stat().st_size > 10_000 and (art / "filmstrip.png").is_file()
    assert load_attrs(art / "ppo.h5").get("slim")  # the skill's policy, logged (jt play RUN replays it)
    params = run_.data.params
    assert params["task.evaluate"] == "fosbury" and params["action.prior"] == str(skill.folder / "prior.h5")
    assert params["curriculum.z_min"] == "0.5" and params["seed"] == "0"


def test_a_skill_name_composes_the_skills_settings_under_the_command_lines(tmp_path):
    cfg = _compose(tmp_path, "task.evaluate=fosbury")
    assert cfg.task.name == "highjump" and cfg.search.name == "single" and cfg.search.budget == 1
    assert cfg.action.name == "pvae" and cfg.action.prior.endswith("skills/fosbury/prior.h5")
    assert cfg.curriculum.dz == pytest.approx(0.02) and cfg.agent.total_samples == 1228800
    mine = _compose(tmp_path, "task.evaluate=fosbury", "seed=3", "search=random", "search.budget=2")
    assert mine.seed == 3 and mine.search.name == "random" and mine.search.budget == 2  # the command line wins


def test_an_unknown_name_lists_the_shipped_skills_in_one_line(tmp_path):
    shipped = r"task.evaluate=nope: no shipped skill of that name \(shipped: [^)]*fosbury"
    with pytest.raises(JtError, match=shipped) as e:
        _compose(tmp_path, "task=highjump", "task.evaluate=nope")
    assert "\n" not in str(e.value) and "train one with: jt run task=highjump" in str(e.value)


@pytest.mark.parametrize("overrides, says", [
    (["sim.sim_hz=300"], r"this run's environment is not the skill's \(its env spec: sim\.sim\.sim_hz=300\.0 "
                         r"\(the skill's 600\.0\)\); leave out the overrides that change it"),
    (["task=obstacle"], r"a skill of task=highjump, this run is task=obstacle"),
    (["experiment=smoke"], r"experiment=smoke replaces the skill's experiment=laptop; leave those out"),
])
def test_a_setting_that_changes_the_skills_environment_is_one_line(tmp_path, overrides, says):
    with pytest.raises(JtError, match=says) as e:
        _compose(tmp_path, "task.evaluate=fosbury", *overrides)
    assert "\n" not in str(e.value) and str(e.value).count("task.evaluate") >= 1
