"""``jt bench rollout``'s training measurement (``toolkit.rl.train_bench``): a real ``jt run``."""

from __future__ import annotations

import pytest


def test_training_reads_the_speed_of_a_real_run(tmp_path):
    """``training`` runs ``jt run`` (real store, real PyBullet, the spacetime preset's 1024-512 nets)
    for two tiny iterations and reads the evaluation's ``ppo.h5``: the first iteration left out."""
    from toolkit.rl.rollout_bench import format_table
    from toolkit.rl.train_bench import training

    over = ["agent.samples_per_iteration=256", "agent.minibatch_size=64"]
    row = training("spacetime", over, n_workers=1, iterations=2, store_dir=tmp_path / "store")
    assert row["iterations"] == 2 and row["iterations_used"] == 1 and not row["warmup_included"]
    assert row["samples_per_iteration"] == 256 and row["agent"] == "ppo_spacetime"
    assert row["policy_hidden"] == [1024, 512]  # the task's own networks
    assert "task.eval_every=1000000000" in row["overrides"] and "task.filmstrip_frames=0" in row["overrides"]
    for key in ("samples_per_s", "collect_s", "update_s"):
        assert len(row[key]) == 2 and all(v > 0 for v in row[key])
    assert row["collect_share"] + row["update_share"] == pytest.approx(1.0)
    assert row["train_samples_per_s"] > 0 and row["wall_s"] >= row["train_wall_s"] > 0
    # iteration 2 alone: its samples over its collect + update
    assert row["train_samples_per_s"] == pytest.approx(256 / (row["collect_s"][1] + row["update_s"][1]), rel=1e-6)
    res = {"task": "spacetime", "overrides": over, "env": [], "collection": [], "training": [row]}
    text = format_table(res)
    assert "PPO training as jt run (agent=ppo_spacetime, 1024-512 nets, 256 samples/iteration)" in text
    assert ("PPO update is" in text) == (row["update_share"] > 0.25)
    heavy = {**row, "update_share": 0.4, "collect_share": 0.6}  # the note a reader gets when updates weigh
    assert "PPO update is 40 % of training wall time" in format_table({**res, "training": [heavy]})
