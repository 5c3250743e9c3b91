"""Eq 11 importance sampling and eq 12 initial-state evolution (002 §4.3): formulas, the sampler,
the env's starts from its payload, and PPO's ``visits`` (real PyBullet)."""

from __future__ import annotations

import numpy as np
import pytest

from jt_tasks.spacetime import sampling as sm

from spacetime_helpers import make_env

W = [10.0, 15.0, 20.0]  # the research notes' worked example


def _defaults(**changes):
    """``SpacetimeConfig()``'s sampling knobs (the paper's), with ``changes`` applied."""
    import dataclasses

    from jt_tasks.spacetime.config import SpacetimeConfig

    return dataclasses.replace(SpacetimeConfig().sampling_params(), **changes)


@pytest.mark.parametrize("reading, expected", [("paper", [0.695, 0.207, 0.098]), ("code", [0.472, 0.312, 0.216])])
def test_eq11_worked_example_both_readings(reading, expected):
    p = sm.is_probabilities(W, 0.2, reading)
    assert np.allclose(p, expected, atol=1e-3) and p.sum() == pytest.approx(1.0)


@pytest.mark.parametrize("reading, expected", [("paper", [0.507, 0.307, 0.186]), ("code", [0.039, 0.176, 0.785])])
def test_eq12_worked_example_both_readings(reading, expected):
    p = sm.boltzmann_probabilities(W, reading)
    assert np.allclose(p, expected, atol=1.5e-3) and p.sum() == pytest.approx(1.0)


def test_equal_returns_give_uniform_and_segments_clip():
    assert np.allclose(sm.is_probabilities([3.0] * 4), 0.25)
    assert np.allclose(sm.boltzmann_probabilities([3.0] * 5), 0.2)
    assert list(sm.segment_of([0.0, 0.099, 0.1, 0.95, 1.0, 1.3], 10)) == [0, 0, 1, 9, 9, 9]


def starts_with_low_segment(low: int, n: int = 10, per: int = 5) -> list[dict]:
    rng = np.random.default_rng(0)
    out = []
    for k in range(n):
        for _ in range(per):
            out.append({"start_phase": (k + rng.uniform()) / n, "target": 2.0 if k == low else 15.0 + rng.uniform()})
    return out


def test_importance_weights_favour_the_segment_with_low_returns():
    s = sm.StartSampler(_defaults(), {}, seed=0)
    for it in range(3):
        pay = s.update(it + 1, 4096 * (it + 1), type("S", (), {"starts": starts_with_low_segment(3)})())
    p = pay["start_sampling"]["probs"]
    assert int(np.argmax(p)) == 3 and p[3] > 0.5
    assert p.min() >= 0.2 / 10 - 1e-12 and p.sum() == pytest.approx(1.0)
    h = s.history()
    assert h["probs"].shape == (3, 10) and h["samples"][-1] == 3 * 4096
    # the running average (0.99, authors' code) moves w by 1 % of the batch mean per iteration
    assert s.state["w"][3] == pytest.approx(2.0 * (1 - 0.99 ** 3))


def test_importance_off_is_uniform():
    s = sm.StartSampler(_defaults(importance_sampling=False), {}, seed=0)
    p = s.update(1, 10, type("S", (), {"starts": starts_with_low_segment(3)})())["start_sampling"]["probs"]
    assert np.allclose(p, 0.1)


def visits(n: int, seed: int, d: int = 5) -> list[dict]:
    rng = np.random.default_rng(seed)
    return [{"state": np.concatenate([[rng.uniform()], rng.normal(size=d - 1)]), "target": float(rng.uniform(0, 20))}
            for _ in range(n)]


@pytest.mark.parametrize("reading", ["paper", "code"])
def test_evolution_keeps_m_states_per_segment_and_leans_as_its_reading(reading):
    params = _defaults(evolution=True, evolution_size=20, evolution_reading=reading,
                      decay=0.95 if reading == "code" else 1.0)
    s = sm.StartSampler(params, {}, seed=0)
    v = visits(2000, 1)
    s.refresh(v, 1)
    st = s.state
    assert list(st["count"]) == [20] * 10 and st["states"].shape == (10, 20, 5)
    seg = sm.segment_of(st["states"][:, :, 0], 10)
    assert (seg == np.arange(10)[:, None]).all()  # every buffer state lies in its own segment
    mean_all, mean_kept = np.mean([x["target"] for x in v]), st["values"].mean()
    # paper: exp(-w / (max - min)) keeps lower returns (uniform w on [0, 20]: expected 8.4 vs 10); code: higher
    assert (mean_kept < mean_all - 0.8) if reading == "paper" else (mean_kept > mean_all + 2)
    s.refresh(visits(30, 2), 2)  # few new candidates: the old buffer competes (m kept)
    assert list(s.state["count"]) == [20] * 10


def test_evolution_is_seeded():
    def run(seed):
        s = sm.StartSampler(_defaults(evolution=True, evolution_size=8), {}, seed=seed)
        s.refresh(visits(500, 3), 1)
        return s.state["states"].copy()

    assert np.array_equal(run(0), run(0)) and not np.array_equal(run(0), run(1))


def test_env_draws_starts_from_the_payload():
    env = make_env(seed=0, sampling={"evolution": True})
    try:
        probs = np.full(10, 0.0)
        probs[7] = 1.0
        env.start_sampling = {"probs": probs}
        phases = [env.reset(seed=s)[1]["start_phase"] for s in range(6)]
        assert all(0.7 <= p < 0.8 for p in phases)
        s0 = env.visit_state()
        q, qd = env.sim.state()
        assert s0.shape == (1 + len(q) + len(qd),) and s0[1] == 0.0 and s0[3] == 0.0
        assert s0[0] == pytest.approx(phases[-1]) and np.allclose(s0[4:1 + len(q)], q[3:])
        # a buffer state of segment 7: started from it, root x, z at the reference's
        state = s0.copy()
        state[1 + len(q) + 6:] += 0.3  # other joint velocities than the reference's
        states = np.zeros((10, 2, len(state)))
        states[7, 0] = state
        env.start_sampling = {"probs": probs, "states": states, "count": np.array([0] * 7 + [1, 0, 0]), "share": 1.0}
        _, info = env.reset(seed=11)
        assert info["from_buffer"] == 1.0 and info["start_segment"] == 7.0
        q1, qd1 = env.sim.state()
        ref = env.ref.sample(env.t0)
        assert q1[0] == pytest.approx(ref.q[0]) and q1[2] == pytest.approx(ref.q[2])
        assert np.allclose(qd1[6:], state[1 + len(q) + 6:], atol=1e-6)
        env.start_sampling = {**env.start_sampling, "share": 0.0}
        assert env.reset(seed=12)[1]["from_buffer"] == 0.0
        env.reset(seed=0, options={"evaluate": True, "phase": 0.0})
        assert env.visit_state() is None  # the evaluation reports nothing
    finally:
        env.close()


def test_ppo_reports_visits_with_targets_and_the_starts_follow_the_payload():
    from toolkit.rl import ppo
    from toolkit.rl.config import PPOConfig

    from toolkit.policy.train import EnvFactory
    from jt_tasks.spacetime.env import SpacetimeEnv

    from spacetime_helpers import make_spec

    spec = make_spec(sampling={"evolution": True}, time_limit=0.5)
    sampler = sm.StartSampler(_defaults(evolution=True, evolution_size=4, n_segments=4), {}, seed=0)
    seen: list = []

    def on_iteration(it, samples, stats):
        seen.append((len(stats.visits), [s["start_segment"] for s in stats.starts],
                     [s["from_buffer"] for s in stats.starts], stats.visits[0]))
        return sampler.update(it, samples, stats)

    cfg = PPOConfig(policy_hidden=(16,), value_hidden=(16,), samples_per_iteration=32, minibatch_size=16,
                    envs_per_worker=2, total_samples=96, seed=0, gamma=0.95, lam=0.95, epochs=1,
                    reset_each_iteration=False)
    ppo.train(EnvFactory(SpacetimeEnv, spec), cfg, on_iteration=on_iteration)
    assert [n for n, *_ in seen] == [32, 32, 32]  # one visit per batch row
    v = seen[0][3]
    assert {"state", "target", "value", "env", "step"} <= set(v) and np.isfinite(v["target"])
    assert all(k == -1.0 for k in seen[0][1])  # before any payload: uniform RSI
    assert all(k >= 0 for k in seen[2][1]) and any(b == 1.0 for b in seen[2][2])  # then eq 11 / eq 12
    assert sampler.state["count"].sum() > 0


def evaluate(workdir, *overrides):
    from toolkit import plugins
    from toolkit.config import compose
    from toolkit.interfaces.task import EvalContext

    cfg = compose(["task=spacetime", "experiment=smoke", "task.evolution=true", "task.evolution_size=8",
                   "agent.total_samples=192", *overrides])
    return plugins.load("task", "spacetime")(cfg).evaluate({}, EvalContext(index=0, seed=3, workdir=workdir))


def test_task_logs_the_is_distribution_per_iteration_seeded_and_resumable(tmp_path):
    import h5py

    ev = evaluate(tmp_path / "a")
    assert {"start_sampling.h5", "start_sampling.png", "ppo.h5", "rollout.h5", "com_bounds.png"} <= set(ev.artifacts)
    with h5py.File(tmp_path / "a" / "start_sampling.h5") as f:
        probs, count = f["probs"][()], f["count"][()]
    assert probs.shape == (3, 10) and np.allclose(probs.sum(axis=1), 1.0) and count[-1].sum() > 0
    assert 0.1 < ev.metrics["is_max_prob"] <= 1.0 and len(ev.history["is_max_prob"]) == 3
    again = evaluate(tmp_path / "b")
    with h5py.File(tmp_path / "b" / "start_sampling.h5") as f:
        assert np.array_equal(f["probs"][()], probs)  # same seed, same distribution
    # a finished run's folder resumes from its ppo.h5: the same distribution, nothing retrained
    resumed = evaluate(tmp_path / "a")
    assert resumed.metrics["samples"] == ev.metrics["samples"] == again.metrics["samples"]
    with h5py.File(tmp_path / "a" / "start_sampling.h5") as f:
        assert np.array_equal(f["probs"][()], probs)


def test_sampling_knobs_are_checked_in_one_line():
    from toolkit.errors import JtError

    from test_spacetime_task import task

    for override, match in [("task.is_reading=both", "paper or code"), ("task.evolution_share=1.5", r"\[0, 1\]"),
                            ("task.mix=2", "eq 13"), ("task.n_segments=0", ">= 1")]:
        with pytest.raises(JtError, match=match) as e:
            task(override)
        assert "\n" not in str(e.value)


def test_code_reading_fills_in_the_authors_defaults():
    from test_spacetime_task import task

    t, _ = task("task.evolution=true", "task.evolution_reading=code")
    p = t.params.sampling_params()
    assert (p.evolution_share, p.evolution_warmup, p.decay, p.importance_sampling) == (0.8, 400, 0.95, True)
    t, _ = task("task.termination=contact")
    p = t.params.sampling_params()
    assert (p.evolution_share, p.evolution_warmup, p.decay, p.importance_sampling, p.evolution) == (1.0, 0, 1.0, False, False)


def test_evaluation_during_training_ends_on_the_final_policys_survival(tmp_path):
    ev = evaluate(tmp_path, "task.eval_every=1", "task.evolution=false")
    curve = ev.history["survival_s"]
    assert [s for s, _ in curve] == [64, 128, 192]  # after every iteration
    assert all(0 < v <= 1.0 for _, v in curve)  # smoke: a 1 s evaluation
    assert curve[-1][1] == pytest.approx(ev.metrics["survival_s"])  # same policy, the same 4 deterministic starts
    worst = ev.history["survival_min_s"]
    assert [s for s, _ in worst] == [64, 128, 192] and all(w <= v + 1e-12 for (_, w), (_, v) in zip(worst, curve))
    assert ev.metrics["survival_min_s"] <= ev.metrics["survival_s"] <= 1.0
    assert "survival_first_s" in ev.metrics  # the final rollout's own episode (from eval_phase)
    assert "samples_to_20s" not in ev.metrics  # never survived


def test_the_evaluation_starts_from_evenly_spread_phases_and_reports_mean_and_min():
    from jt_tasks.spacetime.training import SpacetimeTraining

    from spacetime_helpers import make_env

    class Still:  # a policy of zero corrections: the FFC alone
        def act(self, obs):
            return np.zeros(28)

    hook = SpacetimeTraining(None, lambda: make_env(seed=0, clip="walk", eval_time_limit=2.0),
                             {"phase": 0.1, "evaluate": True}, 1, {}, n_starts=4)
    assert hook.phases() == pytest.approx([0.1, 0.35, 0.6, 0.85])
    mean, share, worst = hook.evaluate(Still())
    singles = []
    for phase in hook.phases():
        one = SpacetimeTraining(None, lambda: make_env(seed=0, clip="walk", eval_time_limit=2.0),
                                {"phase": phase, "evaluate": True}, 1, {}, n_starts=1)
        singles.append(one.evaluate(Still())[0])
    assert mean == pytest.approx(np.mean(singles)) and worst == pytest.approx(min(singles))
    assert 0.0 <= share <= 1.0 and worst < 2.0


def test_samples_to_20s_is_the_first_evaluation_where_every_start_survived():
    from jt_tasks.spacetime.training import samples_to_20s

    rows = np.array([[4096, 3.0, 0, 1.0], [8192, 15.0, 0.75, 0.2], [12288, 20.0, 1, 20.0], [16384, 7.0, 0, 3.0]])
    assert samples_to_20s(rows) == 12288 and samples_to_20s(rows[[0, 1, 3]]) is None
