"""task=spacetime: composition, its groups, the env spec, one-line config errors."""

from __future__ import annotations

import numpy as np
import pytest

from toolkit.errors import JtError


def task(*overrides):
    from toolkit import plugins
    from toolkit.config import compose

    cfg = compose(["task=spacetime", *overrides])
    return plugins.load("task", "spacetime")(cfg), cfg


def test_composes_with_its_groups_and_every_field_has_a_source():
    import dataclasses

    from jt_tasks.spacetime.config import SpacetimeConfig

    t, cfg = task()
    assert cfg.action.name == "ffc_fbc" and cfg.agent.name == "ppo_spacetime" and cfg.spd.name == "df"
    assert cfg.agent.gamma == 0.95
    import inspect

    from toolkit.policy.task import PolicyConfig

    text = inspect.getsource(SpacetimeConfig)
    inherited = {f.name for f in dataclasses.fields(PolicyConfig)} - set(SpacetimeConfig.__dict__.get("__annotations__", {}))
    for f in dataclasses.fields(SpacetimeConfig):
        if f.name in inherited:  # documented once, in the policy layer's PolicyConfig
            continue
        after = text.split(f"    {f.name}:", 1)[1].split("\n", 2)[1].strip()
        assert after.startswith('"""'), f.name
        if f.name not in ("name", "filmstrip_frames", "filmstrip_width", "filmstrip_height"):
            assert "002" in after or "ours" in after or "authors" in after, f.name


def test_env_spec_feeds_the_task_clip_to_the_ffc_and_picks_the_heading_axis():
    t, _ = task("task.clip=backflip")
    spec = t.env_spec({})
    assert spec.action["clip"].endswith("humanoid3d_backflip.txt")
    assert spec.heading_axis == "z" and len(spec.widths) == 22
    t, _ = task("task.clip=cartwheel", "task.heading_axis=x")
    spec = t.env_spec({})
    assert spec.heading_axis == "x" and set(spec.eval_allowed) == {5, 11, 8, 14}
    t, _ = task("task.clip=roll")
    assert len(t.env_spec({}).eval_allowed) == 16  # roll: everything may touch


def test_a_spacetime_spec_without_heading_or_contacts_resolves_them_per_clip():
    from spacetime_helpers import make_env

    env = make_env(clip="roll")
    assert env.axis == "z" and len(env.eval_allowed) == env.n_links + 1  # roll: every link may touch
    env = make_env(clip="run")
    assert env.axis == "x" and env.eval_allowed == (5, 11)


@pytest.mark.parametrize("override, match", [
    ("task.clip=no_such_clip", "no such clip"),
    (f"task.clip={__file__}", "not a DeepMimic"),
    ("task.com_width=0", "must be > 0"),
    ("task.end_effector_width=-0.5", "must be > 0"),
    ("+task.widths.elbow=0.5", "unknown bound channel"),
    ("+task.widths.neck=0", "must be > 0"),
    ("task.heading_axis=y", "x or z"),
    ("task.termination=falls", "bounds"),
    ("task.time_limit=0", "> 0"),
    ("task.allowed_contacts=[hand]", "unknown link"),
])
def test_bad_input_is_one_line_error_at_composition(override, match):
    with pytest.raises(JtError, match=match) as e:
        task(override)
    assert "\n" not in str(e.value)


def test_quick_and_paper_presets_compose_with_the_papers_batch():
    _, quick = task("experiment=quick")
    _, paper = task("experiment=paper")
    assert quick.agent.samples_per_iteration == paper.agent.samples_per_iteration == 4096  # 002 §5
    assert quick.agent.total_samples == 3 * 4096 and quick.task.filmstrip_frames > 0
    assert paper.agent.total_samples == 6000 * 4096 and list(paper.agent.policy_hidden) == [1024, 512]
    assert paper.agent.n_workers == 18 and paper.task.eval_time_limit == 20.0


def test_the_table1_preset_is_the_measured_walk_run_with_its_cost():
    """``experiment=table1``: the walk at Table 1's 4.1 M samples, the paper's PPO, the authors'
    output scale, 4 evaluation starts every 10 iterations, 2 workers; a cost line to print first."""
    t, cfg = task("experiment=table1")
    assert cfg.task.clip == "walk" and cfg.agent.total_samples == 1001 * 4096 and cfg.agent.n_workers == 2
    assert cfg.agent.policy_lr == 2.5e-6 and cfg.agent.optimizer == "sgd" and cfg.action.output_scale == "range"
    assert (cfg.task.eval_every, cfg.task.eval_starts, cfg.task.termination) == (10, 4, "bounds")
    assert "min" in str(cfg.cost) and "2 cores" in str(cfg.cost) and str(cfg.cost).startswith("4100096 samples")
    _, half = task("experiment=table1", "agent.total_samples=2048000")
    assert str(half.cost).startswith("2048000 samples")  # the cost line says the budget the run has
    _, run = task("experiment=table1", "task.clip=run")
    assert run.task.clip == "run" and run.agent.total_samples == cfg.agent.total_samples


@pytest.mark.parametrize("preset, clip, term, mode, widths", [
    ("style_walk_low_volume", "walk", "volume", "decrease", {"right_knee": 1.0, "neck": 0.7, "root": 0.7, "com_y": 0.2}),
    ("style_run_high_energy", "run", "energy", "increase", {"left_hip": 1.0, "right_elbow": 1.0, "chest": 0.7}),
    ("style_cartwheel_low_energy", "cartwheel", "energy", "decrease",
     {"chest": np.inf, "right_knee": np.inf, "ee_left_wrist": np.inf, "root": 0.7, "neck": 1.0, "left_ankle": 1.0,
      "com_x": 0.3, "com_y": 0.2, "com_z": 0.3}),  # the authors' style_cartwheel.txt
    ("style_dance_high_energy", "dance_a", "energy", "increase", {"left_shoulder": 1.0, "root": 0.7, "ee_right_ankle": 0.5}),
])
def test_style_presets_loosen_the_bounds_and_add_their_term(preset, clip, term, mode, widths):
    """002 §5.3.1's style runs as presets: the clip, the style term and the loosened bounds."""
    from jt_tasks.spacetime.bounds import channel_names
    from toolkit.motion.skeletons import HUMANOID

    t, cfg = task(f"preset={preset}")
    assert cfg.task.clip == clip and [dict(s) for s in cfg.task.style] == [{"name": term, "mode": mode}]
    spec = t.env_spec({})
    names = channel_names(HUMANOID)
    for channel, w in widths.items():
        assert spec.widths[names.index(channel)] == w, channel


def test_the_laptop_preset_is_the_setting_measured_to_reach_20_s():
    """``experiment=laptop``: ``experiment=table1``'s walk with the three measured deviations (the
    FFC's lead and target velocities, the CoM in height only), the links' velocities, 2.05 M samples;
    its cost line first; the horizontal CoM box comes back as the preset's comment says."""
    from jt_tasks.spacetime import bounds as bd
    from toolkit.motion.skeletons import HUMANOID

    _, table1 = task("experiment=table1")
    _, cfg = task("experiment=laptop")
    assert cfg.task.clip == "walk" and cfg.agent.total_samples == 500 * 4096 and cfg.agent.n_workers == 2
    assert (cfg.task.ffc_lead, cfg.task.ffc_velocity, cfg.task.velocities) == (1, True, "links")
    for key in ("policy_lr", "optimizer", "samples_per_iteration"):
        assert cfg.agent[key] == table1.agent[key], key
    assert (cfg.task.eval_every, cfg.task.eval_starts, cfg.task.termination) == (10, 4, "bounds")
    w = bd.widths(HUMANOID, cfg.task.com_width, cfg.task.orientation_width, cfg.task.end_effector_width,
                  dict(cfg.task.widths))
    assert np.isinf(w[0]) and w[1] == 0.2 and np.isinf(w[2]) and np.isfinite(w[3:]).all()  # CoM x, z off
    assert str(cfg.cost).startswith("2048000 samples") and "2 cores" in str(cfg.cost)
    _, box = task("experiment=laptop", "task.widths.com_x=0.2", "task.widths.com_z=0.2")
    wb = bd.widths(HUMANOID, box.task.com_width, box.task.orientation_width, box.task.end_effector_width,
                   dict(box.task.widths))
    assert np.allclose(wb[:3], 0.2)
    _, run = task("experiment=laptop", "task.clip=run")
    assert run.task.clip == "run" and run.agent.total_samples == cfg.agent.total_samples


def test_jt_play_start_is_the_clip_phase():
    t, _ = task("task.eval_phase=0.1")
    assert t.play_options(None) == {"phase": 0.1, "evaluate": True}
    assert t.play_options(None, "0.25") == {"phase": 0.25, "evaluate": True}
    for bad in ("1.5", "x", "nan"):
        with pytest.raises(JtError, match=r"--start=.*: task=spacetime starts at a clip phase in \[0, 1\]"):
            t.play_options(None, bad)


class _Still:
    """Zero corrections: the feed-forward alone (the clip's pose ahead)."""

    def __init__(self, n: int) -> None:
        self.n = n

    def act(self, obs):
        return np.zeros(self.n)


def test_jt_play_summary_says_how_long_it_survived_from_which_phase():
    from toolkit.policy.episodes import opened_env, rollout

    t, _ = task("task.clip=walk")
    with opened_env(t.make_env, {}, seed=0) as env:
        still = _Still(env.action_space.shape[0])
        ro = rollout(env, still, t.record, options=t.play_options(env, "0.25"))
        measure, line = t.play_summary(env, ro)
        assert measure["survived"] is False and measure["start_phase"] == 0.25
        assert 0.0 < measure["survival_s"] < 5.0  # the feed-forward alone falls within seconds
        assert line.startswith(f"walk: fell at {measure['survival_s']:.2f} s (") and "from clip phase 0.25" in line
        ro = rollout(env, still, t.record, options=t.play_options(env, "0.25"), max_steps=3)
        measure, line = t.play_summary(env, ro)
    assert measure == {"survival_s": 0.1, "survived": False, "start_phase": 0.25}
    assert line.startswith("walk: still up at 0.10 s from clip phase 0.25")
