"""``policy_bounds``: Table 1's evaluation with the bounds watched, for a trained run's policy."""

from __future__ import annotations

import numpy as np
import pytest

from jt_tasks.spacetime.analysis import bounds_study, policy_bounds
from tests.plugins.jt_tasks.spacetime.spacetime_helpers import make_env


class _FFCAlone:
    """The zero correction: the feed-forward controller alone (bounds_study's policy)."""

    def __init__(self, n: int) -> None:
        self.n = n

    def act(self, obs):
        return np.zeros(self.n, np.float32)


def test_the_ffc_alone_leaves_its_first_bound_when_bounds_study_says():
    """Two tools, one episode: the first violation's time is bounds_study's first step outside."""
    env = make_env()
    try:
        steps = int(1.0 * env.control_hz)
        ep = bounds_study.episode(env, 0.3, steps)
        got = policy_bounds.watch(env, _FFCAlone(env.action_space.shape[0]), 0.3, steps)
    finally:
        env.close()
    assert ep["first"] is not None  # the untrained FFC leaves the run's bounds within 1 s
    assert min(got["first"].values()) == pytest.approx((ep["first"] + 1) / env.control_hz)
    assert got["seconds"] == pytest.approx(ep["steps"] / env.control_hz)
    first_out = min(got["first"], key=got["first"].get)
    assert got["peak"][list(env.names).index(first_out)] > 1.0  # a channel that left its bound peaks above 1


def test_a_trained_runs_policy_is_reported_per_start(tmp_path, capsys):
    from omegaconf import OmegaConf

    from toolkit import plugins
    from toolkit.config import compose
    from toolkit.interfaces.task import EvalContext

    cfg = compose(["task=spacetime", "experiment=smoke"])
    plugins.load("task", "spacetime")(cfg).evaluate({}, EvalContext(index=0, seed=3, workdir=tmp_path))
    OmegaConf.save(cfg, tmp_path / "config.yaml")
    policy_bounds.main([str(tmp_path / "ppo.h5"), "--starts", "2", "--seconds", "0.5"])
    lines = capsys.readouterr().out.strip().splitlines()
    assert len(lines) == 4 and lines[2].startswith("| 0.000 |") and lines[3].startswith("| 0.500 |")
    for row in lines[2:]:
        assert 0.0 < float(row.split("|")[2]) <= 0.5


@pytest.mark.parametrize("argv, match", [
    (["nosuchrun", "--store", "{tmp}"], "run=nosuchrun: no such run"),
    (["{tmp}/x.h5", "--starts", "0"], "--starts=0: at least 1"),
    (["{tmp}/x.h5", "--seconds", "nan"], "--seconds=nan: a finite number"),
    (["{tmp}/getup/ppo.h5"], "{tmp}/getup/ppo.h5: a task=getup run; jt study spacetime policy-bounds reads "
                             "task=spacetime runs"),
    (["{tmp}/x.h5", "--starts"], "jt study spacetime policy-bounds: argument --starts: expected one argument"),
])
def test_bad_input_is_one_line(tmp_path, capsys, argv, match):
    from omegaconf import OmegaConf

    from toolkit.config import compose

    (tmp_path / "getup").mkdir()
    (tmp_path / "getup" / "ppo.h5").write_bytes(b"never read")
    OmegaConf.save(compose(["task=getup", "experiment=smoke"]), tmp_path / "getup" / "config.yaml")
    match = match.replace("{tmp}", str(tmp_path))
    with pytest.raises(SystemExit) as e:
        policy_bounds.main([a.replace("{tmp}", str(tmp_path)) for a in argv])
    assert e.value.code == 2
    err = capsys.readouterr().err.strip()
    assert match in err and len(err.splitlines()) == 1
