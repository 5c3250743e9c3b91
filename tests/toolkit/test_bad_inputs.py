"""User mistakes found by a probe of bad inputs: each is one ``JtError`` line at composition, before
a prior is trained or a run opens, and no store is created (issue "Trust the store")."""

from __future__ import annotations

import pytest

from toolkit.errors import JtError

CASES = [
    (["task=highjump", "task.clip=nope"], r"task.clip=nope: one of .*run"),
    (["task=highjump", "task.clip=/no/such/clip.txt"], r"task.clip=/no/such/clip.txt: no such file"),
    (["task=spd_tracking", "task.motion=nope"], r"task.motion=nope: no motion 'nope' for humanoid; choose one of"),
    (["task=spd_tracking", "character=laikago", "task.motion=nope"], r"task.motion=nope: .*laikago; choose one of: walk"),
    (["task=highjump", "action=pvae", "action.prior=/no/such/prior.h5"], r"action.prior=/no/such/prior.h5: no such file"),
    (["task=highjump", "curriculum.dz=0"], r"curriculum.dz=0.0: must be > 0"),
    (["task=highjump", "curriculum.z_min=nan"], r"curriculum.z_min=nan: must be a finite number"),
    (["task=highjump", "curriculum.z_freeze=3"], r"curriculum.z_freeze=3.0: must lie in \[z_min, z_max\]"),
    (["task=obstacle", "curriculum.z_max=0.01"], r"curriculum.z_max=0.01: must be >= z_min"),
    (["task=highjump", "search=bds", "search.failures=never"], r"search.failures='never': choose one of avoid, believe"),
    (["task=highjump", "search=bds", "search.n_init=0"], r"search.n_init=0: must be >= 1"),
    (["task=highjump", "search=bds", "search.feature_distance=manhattan"], r"search.feature_distance=manhattan: one of angle"),
    (["task=highjump", "search=bds", "search.init_method=grid"], r"search.init_method=grid: uniform or sobol"),
    (["task=zdt1", "search=random", "search.method=grid"], r"search.method=grid: uniform or sobol"),
    (["task=standing_jump", "search=rmoo", "search.mu=0"], r"search.mu=0: must be >= 1"),
    (["task=standing_jump", "search=rmoo", "search.success=best"], r"search.success=best: one of parent, selected"),
    (["task=zdt1", "seed=-1"], r"seed=-1: must be an integer >= 0"),
    (["task=zdt1", "executor.workers=-1"], r"executor.workers=-1: a count of workers >= 0"),
    (["task=zdt1", "executor.start_method=nope"], r"executor.start_method=nope: spawn, forkserver or fork"),
    (["task=spd_tracking", "spd=pcg", "spd.tol=-1"], r"spd.tol=-1.0: must be a finite number > 0"),
    (["task=highjump", "character.joint_kp={nope: 150.0}"], r"character 'humanoid' has no movable joint 'nope'; joints: chest"),
    (["task=zdt1", "reward=highjump"], r"task=zdt1 does not read a reward group; drop the reward= choice"),
    (["task=standing_jump", "action=pvae"], r"task=standing_jump does not read an action group; drop action=pvae"),
    # issue 30: values that ran (or failed after the run opened)
    (["~task"], r"a run needs a task: task=<name>; choose one of: .*getup"),
    (["task=zdt1", "executor=ray", "executor.address=127.0.0.1:1"], r"executor.address=127.0.0.1:1: no Ray cluster answers"),
    (["task=spacetime", "action.clip=/no/such.txt"], r"action=ffc_fbc: no clip '/no/such.txt'; give a path or one of"),
    (["task=pose_prior", "action=pvae", "task.dataset=/no/such.h5"], r"task.dataset=/no/such.h5: not a jt pose dataset"),
    (["task=spd_tracking", "task.rates_hz=[]"], r"task.rates_hz=\[\]: one or more rates > 0 Hz"),
    (["task=spd_tracking", "task.duration=-1"], r"task.duration=-1.0: must be >= 0 s"),
    (["task=getup", "action=raw", "task.terrain=null", "task.eval_regions=[flat,hard]"],
     r"only flat without a terrain \(task.terrain=null\)"),
    # issue 55: combinations refused before the run row (they failed after it)
    (["task=spd_tracking", "spd=servo"], r"spd=servo cannot drive the tracking's root servo"),
    (["task=standing_jump", "spd=servo"], r"spd=servo computes its torques inside the simulator's step, and "
                                          r"task=standing_jump needs the torques; use one of: df, maba, pcg, sf"),
    (["task=spd_tracking", "character=snake36", "task.motion=walk"], r"the snakes track the generated 'slither'"),
    (["task=spd_tracking", "task.motion=slither"], r"task.motion=slither is for the snakes"),
    (["task=spd_tracking", "character=atlas"], r"character=atlas: no motion to track"),
    (["task=highjump", "spd=servo", "sim.root_servo.kp=100"], r"spd=servo cannot drive a root servo"),
    # issue 55: messages that name the key and the fix
    (["task=highjump", "task.ranges={alpha: abc}"], r"task.ranges.alpha=abc: needs finite \[low, high\]"),
    (["task=zdt1", "=x"], r"bad override '=x': no key before '='; write KEY=VALUE"),
    (["task=zdt1", "run_name=höhe"], r"must be quoted: run_name='höhe' \(on a shell command line"),
    # issue 55: values that would silently do nothing
    (["task=spacetime", "task.straighten=true", "task.loop=false"], r"task.straighten=True: .*does nothing on a clip"),
    (["task=getup", "action=raw", "task.rsi=0.5", "task.p_standing=0.5", "task.p_fallen=0.5"],
     r"task.rsi=0.5: shapes the episodes that start from a clip"),
]


@pytest.mark.parametrize("overrides, message", CASES, ids=[" ".join(c[0][1:]) for c in CASES])
def test_a_mistake_is_one_line_before_anything_runs(overrides, message, tmp_path):
    from toolkit.config import compose

    store = tmp_path / "store"
    with pytest.raises(JtError, match=message) as e:
        compose([*overrides, f"store={store}"])
    assert "\n" not in str(e.value)
    assert not store.exists()


def test_the_task_checks_its_run_before_the_store_s_prior_is_trained(tmp_path):
    """``action.prior=auto`` trains a prior on first use (a minute); a task mistake the task itself
    finds (Stage 2 without its novelty reward) must come first, with nothing written."""
    from toolkit.config import compose
    from toolkit.execution.runner import run

    store = tmp_path / "store"
    cfg = compose(["task=highjump", "task.stage=2", f"store={store}"])
    assert str(cfg.action.prior) == "auto"
    with pytest.raises(JtError, match="task.stage=2: the reward has no 'novelty' term"):
        run(cfg)
    assert not store.exists()


@pytest.mark.parametrize("search", ["rmoo", "bsoo"])
def test_a_searcher_that_does_not_fit_the_task_is_one_line_before_anything_runs(search, tmp_path):
    from toolkit.config import compose
    from toolkit.execution.runner import run

    store = tmp_path / "store"
    with pytest.raises(JtError, match=f"search={search} needs a task with"):
        run(compose(["task=highjump", f"search={search}", f"store={store}"]))
    assert not store.exists()


def test_a_comparison_cannot_vary_its_store(tmp_path):
    """--vary store=A,B (issue 30): one line, nothing written."""
    from toolkit.execution.compare import compare

    with pytest.raises(JtError, match=r"bad --vary 'store=.*': a comparison and its runs live in one store"):
        compare(["task=zdt1", f"store={tmp_path / 's'}"], [f"store={tmp_path / 'a'},{tmp_path / 'b'}"], 1)
    assert not any((tmp_path / n).exists() for n in ("s", "a", "b"))


def test_files_named_in_a_config_are_read_before_anything_runs(tmp_path):
    """Issue 30, item 2: a garbage trained policy for task.evaluate, a motion file with bad JSON or
    one frame: one line naming the file, no store."""
    import json
    import os

    import pybullet_data

    from toolkit.config import compose

    junk = tmp_path / "junk.h5"
    junk.write_text("junk")
    walk = json.loads(open(os.path.join(pybullet_data.getDataPath(), "data/motions/humanoid3d_walk.txt")).read())
    one = tmp_path / "one.txt"
    one.write_text(json.dumps({**walk, "Frames": walk["Frames"][:1]}))
    store = tmp_path / "store"
    for overrides, message in [
        (["task=getup", "action=raw", f"task.evaluate={junk}"], r"task.evaluate=.*junk.h5 is not a jt PPO checkpoint"),
        (["task=spd_tracking", f"task.motion={junk}"], r"task.motion=.*junk.h5: bad JSON"),
        (["task=spd_tracking", f"task.motion={one}"], r"task.motion=.*one.txt: 'Frames' must be a list of at least 2"),
    ]:
        with pytest.raises(JtError, match=message) as e:
            compose([*overrides, f"store={store}"])
        assert "\n" not in str(e.value)
    assert not store.exists()


def test_an_unknown_progress_mode_is_one_line(tmp_path):
    """``JT_PROGRESS=bars`` was ignored (a bar on a terminal, lines elsewhere, whatever it said)."""
    import os
    import subprocess

    store = tmp_path / "store"
    p = subprocess.run(["jt", "run", "task=zdt1", "experiment=smoke", f"store={store}"], capture_output=True,
                       text=True, env={**os.environ, "JT_PROGRESS": "bars"}, timeout=120)
    assert p.returncode == 2 and p.stderr.strip() == \
        "jt: JT_PROGRESS='bars': choose bar or lines (unset: a bar on a terminal, lines elsewhere)"
    assert not store.exists()
