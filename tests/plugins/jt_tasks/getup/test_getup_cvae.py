"""action=cvae in the get-up task (003 §3.4-3.5): a C-VAE prior from task=pose_prior drives the env;
the decoder's condition is the target curves now; a run trains and rolls out end to end."""

from __future__ import annotations

import math

import numpy as np
import pytest

from toolkit.errors import JtError

FAST = ["task.train_regions=flat", "task.n_fallen=1", "task.settle_max=0.5"]


@pytest.fixture(scope="module")
def priors(tmp_path_factory):
    """``{kind: prior.h5 folder}``: a 2-epoch C-VAE and P-VAE from ``task=pose_prior``."""
    from omegaconf import OmegaConf

    from jt_tasks.pose_prior import PosePriorTask
    from toolkit.interfaces import EvalContext

    out = {}
    for kind in ("cvae", "pvae"):
        work = tmp_path_factory.mktemp(kind)
        task = PosePriorTask(OmegaConf.create({"task": {"name": "pose_prior", "epochs": 2, "samples": 1},
                                               "action": {"name": kind}}))
        task.evaluate({}, EvalContext(index=0, seed=0, workdir=work))
        out[kind] = str(work)
    return out


def getup_cfg(*overrides: str):
    from toolkit.config import compose, validate

    return validate(compose(["task=getup", *FAST, *overrides]))


def test_cvae_condition_is_the_target_curves_now(priors):
    from toolkit import plugins

    task = plugins.load("task", "getup")(getup_cfg("action=cvae", f"action.prior={priors['cvae']}"))
    env = task.make_env(None, seed=0)
    try:
        space = env.action_space_
        assert space.kind == "cvae" and env.action_space.shape == (space.prior.latent_dim + 28,)
        obs, _ = env.reset(seed=0, options={"kind": "clip", "curve": "faceup"})
        a = np.zeros(env.action_space.shape, np.float32)
        a[0] = 1.0
        for k in range(3):
            t = env.t
            obs, r, term, trunc, info = env.step(a)
            np.testing.assert_allclose(space.condition, env.targets(t))  # 003 §3.4: c = p(s) now
            # the state ends with the previous filtered action y_{t-1} (003 §3.3), 0.2-filtered
            np.testing.assert_allclose(obs[-len(a):], space.filtered.astype(np.float32), rtol=1e-6)
        assert space.filtered[0] == pytest.approx(1 - 0.8 ** 3)  # filter step response (003 eq in §3.4)
        assert 0.0 <= env.log[-1]["r_naturalness"] <= 1.0 and math.isfinite(r)
    finally:
        env.close()


def test_a_pvae_prior_given_to_cvae_is_one_line(priors):
    """Found when the config is composed, before a run opens (issue 30, item 2)."""
    from toolkit import plugins

    with pytest.raises(JtError, match="pvae prior, action=cvae needs a cvae one") as e:  # at composition
        plugins.load("task", "getup")(getup_cfg("action=cvae", f"action.prior={priors['pvae']}"))
    assert "\n" not in str(e.value)


def test_getup_with_a_cvae_prior_trains_and_rolls_out(priors, tmp_path):
    """``jt run task=getup action=cvae action.prior=...`` at smoke scale: every artifact."""
    from toolkit import plugins
    from toolkit.interfaces import EvalContext

    cfg = getup_cfg("experiment=smoke", "action=cvae", f"action.prior={priors['cvae']}", "task.eval_regions=[flat]")
    task = plugins.load("task", "getup")(cfg)
    ev = task.evaluate({}, EvalContext(index=0, seed=0, workdir=tmp_path))
    assert ev.metrics["samples"] >= 128 and 0.0 <= ev.metrics["success_overall"] <= 1.0
    assert 0.0 < ev.metrics["r_naturalness_mean"] <= 1.0  # eq 3 from the C-VAE's offsets
    for name in ("ppo.h5", "rollout.h5", "filmstrip.png", "motion.gif", "table1.h5", "curves.png"):
        assert name in ev.artifacts and (tmp_path / name).stat().st_size > 0


def open_loop_noise(task, sigma: float, steps: int, seed: int = 0) -> dict[str, float]:
    """The action filter without learning (issue check 3; docs/journal/getup.md, 2026-12-01): Gaussian
    actions of std ``sigma`` about 0 (the initial policy's mean and std) for ``steps`` control steps
    from the facedown clip's pose (restarted when an episode ends), in ``task``'s own env. Returns
    the mean r_natural (eq 3) and the mean per-step change of the PD targets within an episode (rad
    per DoF per control step), read from each step's own ``pd_targets`` (a subclass that records
    them: nothing else changes)."""

    class Recording(task.env_class):
        def pd_targets(self, action):
            q = super().pd_targets(action)
            self.seen.append(self.skeleton.joints_to_dofs(q[7:]))  # the space's DoF targets, this step's
            return q

    rng = np.random.default_rng(int(seed))
    env = Recording(task.env_spec({}), seed=0)
    env.seen = []
    nat, change = [], []
    try:
        env.reset(seed=0, options={"kind": "clip", "curve": "facedown"})
        low, high = env.action_space.low, env.action_space.high
        for _ in range(int(steps)):
            a = np.clip(rng.normal(0.0, sigma, env.action_space.shape), low, high).astype(np.float32)
            _, _, te, tr, _ = env.step(a)
            nat.append(float(env.log[-1]["r_naturalness"]) if env.log else math.nan)
            if len(env.log) > 1:  # not the first step of an episode
                change.append(float(np.mean(np.abs(env.seen[-1] - env.seen[-2]))))
            if te or tr:
                env.reset(seed=0, options={"kind": "clip", "curve": "facedown"})
    finally:
        env.close()
    return {"r_natural": float(np.nanmean(nat)), "target_change": float(np.mean(change)) if change else math.nan}


def test_the_filter_without_learning_keeps_targets_smooth_and_natural(priors):
    """The issue's check 3 at the initial policy's σ = 0.6 (003 §5.6): with the 0.2 filter r_natural
    stays high and the PD targets move several times less per step than with β = 1 (no filter)."""
    from toolkit import plugins

    out = {}
    for beta in (0.2, 1.0):
        task = plugins.load("task", "getup")(getup_cfg("action=cvae", f"action.prior={priors['cvae']}",
                                                       f"action.beta={beta}"))
        out[beta] = open_loop_noise(task, 0.6, 60, seed=0)
    assert out[0.2]["r_natural"] > 0.6 and out[1.0]["r_natural"] < 0.2  # measured: 0.83 vs 0.01
    assert out[1.0]["target_change"] > 3 * out[0.2]["target_change"]  # measured: 0.61 vs 0.09 rad


def test_a_prior_named_by_run_id_is_looked_up_in_action_store(tmp_path):
    """action.store=DIR is where a prior's run id is looked up (issue 30, item 4), not the run's own
    store; without it, the run's own store is searched and the id is refused in one line."""
    from toolkit.config import compose
    from toolkit.execution.runner import run

    elsewhere = tmp_path / "priors"
    rid = run(compose(["task=pose_prior", "action=cvae", "experiment=smoke", f"store={elsewhere}"])).run_id
    mine = tmp_path / "mine"
    cfg = compose(["task=getup", *FAST, "action=cvae", f"action.prior={rid}", f"action.store={elsewhere}",
                   f"store={mine}"])
    assert cfg.action.prior == rid
    with pytest.raises(JtError, match="action.prior"):
        compose(["task=getup", *FAST, "action=cvae", f"action.prior={rid}", f"store={mine}"])


@pytest.mark.parametrize("content", [b"garbage", b""])
def test_a_prior_file_that_is_not_one_is_refused_at_composition(content, tmp_path):
    from toolkit.config import compose

    bad = tmp_path / "prior.h5"
    bad.write_bytes(content)
    with pytest.raises(JtError, match=r"prior.h5: unreadable pose prior") as e:
        compose(["task=getup", *FAST, "action=cvae", f"action.prior={bad}", f"store={tmp_path / 's'}"])
    assert "\n" not in str(e.value) and not (tmp_path / "s").exists()
