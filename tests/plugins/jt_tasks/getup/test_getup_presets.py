"""experiment=smoke / quick / paper for task=getup compose to what docs/getup.md says."""

from __future__ import annotations

import math

import pytest


def cfg(experiment: str, *more: str):
    """The composed preset, without the cross-group checks a run needs (the paper's C-VAE prior
    must exist for a run; reading its budgets does not need one)."""
    from toolkit.config import compose

    return compose(["task=getup", f"experiment={experiment}", *more], run_checks=False)


@pytest.mark.parametrize("experiment", ["smoke", "quick", "paper"])
def test_no_episode_is_cut_by_the_iteration(experiment):
    """Each env collects at least one whole longest episode (7.6 s authored curve + 3 s standing at
    30 Hz = 318 control steps) per PPO iteration, except at smoke scale."""
    c = cfg(experiment)
    a = c.agent
    per_env = a.samples_per_iteration / (a.n_workers * a.envs_per_worker)
    longest = math.ceil((max(c.task.authored_durations) + c.task.t_stand) * c.sim.control_hz)
    assert longest == 318
    if experiment != "smoke":
        assert per_env >= longest


def test_paper_preset_has_the_papers_budgets():
    c = cfg("paper")
    assert c.action.name == "cvae" and c.agent.total_samples == 100_000_000  # 003 §3.4, §5.6
    assert c.agent.n_workers == 16 and c.agent.minibatch_size == 256  # 003 §5.6
    assert c.task.eval_locations == 100 and list(c.task.eval_regions) == ["flat", "easy", "medium", "hard"]
    assert c.curriculum.name == "terrain" and c.curriculum.successes_to_unlock == 200  # 003 §5.4


def test_quick_preset_visits_every_region_on_a_fixed_schedule():
    c = cfg("quick")
    assert c.agent.total_samples // c.curriculum.fixed_every_samples >= 3  # hard unlocked before the end
    assert c.action.name == "raw" and c.task.eval_locations >= 5


def test_laptop_preset_is_stage_one_on_flat_ground():
    """experiment=laptop (issue 29): the 4 reference curves on flat ground, no curriculum, C-VAE
    actions, obs normalisation, stage 1's 100 perturbed clip starts and Table 1's flat column,
    episodes never cut by an iteration, the std/lr plateaus inside the budget (std halved), the cost stated."""
    c = cfg("laptop")
    a, t = c.agent, c.task
    assert list(t.curves) == ["facedown", "facedown_mirror", "faceup", "faceup_mirror"]
    assert t.terrain is None and "curriculum" not in c and list(t.eval_regions) == ["flat"]
    assert c.action.name == "cvae" and a.obs_norm and t.eval_clip_starts == 100 and t.eval_locations == 100
    assert a.samples_per_iteration / (a.n_workers * a.envs_per_worker) >= math.ceil((3.77 + 3.0) * 30)
    assert max(s for s, _ in a.std_schedule) < a.total_samples and a.std_schedule[-1][1] == 0.15
    assert a.std_schedule[0][1] == 0.3  # half of 003's 0.6: standing learned 3-4x faster (docs/getup.md)
    assert "h on 2 cores" in c.cost
