"""Every task's pictures show the character, at smoke as at paper budget (issue 31): frames at
least 320 px wide, and the character's own pixels (the simulator's segmentation) a visible part of
the first frame of the final rollout, away from the frame's edges."""

from __future__ import annotations

import numpy as np
import pytest

POLICY_TASKS = ["highjump", "obstacle", "longjump", "runup", "getup", "spacetime"]


def composed(task: str, experiment: str = "smoke"):
    from toolkit.config import compose

    return compose([f"task={task}", f"experiment={experiment}"], run_checks=False)


@pytest.mark.parametrize("experiment", ["smoke", "quick", "default"])
@pytest.mark.parametrize("task", POLICY_TASKS)
def test_frames_are_at_least_320_px_wide(task, experiment):
    try:
        c = composed(task, experiment)
    except Exception:  # noqa: BLE001 - a task without this experiment: nothing to draw
        pytest.skip(f"task={task} has no experiment={experiment}")
    assert c.task.filmstrip_width >= 320 and c.task.filmstrip_height >= 200


@pytest.mark.parametrize("task", ["standing_jump", "spd_tracking"])
def test_the_other_tasks_render_at_least_320_px_wide(task):
    t = composed(task).task
    assert (t.get("filmstrip_width") or t.get("render_width")) >= 320


@pytest.mark.parametrize("task", POLICY_TASKS)
def test_the_first_frame_of_the_final_rollout_shows_the_character(task):
    from toolkit import plugins
    from toolkit.config import compose, validate

    cfg = validate(compose([f"task={task}", "experiment=smoke", "action=raw"]))
    t = plugins.load("task", task)(cfg)
    env = t.make_env(None, seed=0)
    try:
        env.reset(seed=0, options=t.final_options(env))
        w, h = int(cfg.task.filmstrip_width), int(cfg.task.filmstrip_height)
        rgb, mask = env.render_frame(w, h, mask=True)
    finally:
        env.close()
    assert rgb.shape == (h, w, 3) and mask.shape == (h, w)
    assert mask.mean() > 0.01, f"the character covers {mask.mean():.2%} of the frame"
    ys, xs = np.nonzero(mask)
    assert xs.min() > 0 and xs.max() < w - 1 and ys.min() > 0 and ys.max() < h - 1  # whole, not cut
    # the character's pixels differ from the background's (a colour check beside the mask)
    assert np.abs(rgb[mask].mean(axis=0) - rgb[~mask].mean(axis=0)).max() > 10
