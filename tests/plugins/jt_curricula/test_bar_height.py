"""bar_height / obstacle_width: the reward accumulator and schedules of 000 §6.1.3, Table 1."""

from __future__ import annotations

import math

import pytest

from toolkit.errors import JtError

from toolkit.testing.curriculum import CurriculumContract, iteration_stats
from jt_curricula import schedules
from jt_curricula.bar_height import BarHeightCurriculum, ObstacleWidthCurriculum


def reward_stream(n: int, per_iteration: float, n_episodes: int = 4):
    """``n`` iterations whose episodes all return ``per_iteration`` (mean_reward 1/20 of it)."""
    eps = [{"return": per_iteration, "length": 20.0, "terminated": 1.0}] * n_episodes
    return [(eps, {"mean_return": per_iteration, "mean_reward": per_iteration / 20, "n_episodes": float(n_episodes)},
             256 * (i + 1)) for i in range(n)]


class TestBarHeight(CurriculumContract):
    cls, entry = BarHeightCurriculum, "bar_height"

    def stream(self, n):
        return reward_stream(n, 7.0)  # a step every 5 iterations (35 > 30)

    def test_table1_defaults(self):
        p = BarHeightCurriculum().params
        assert (p.z_min, p.z_max, p.dz, p.reward_threshold, p.z_freeze) == (0.5, 2.0, 0.01, 30.0, 1.0)
        assert BarHeightCurriculum().max_level == 150

    def test_accumulator_steps_at_the_exact_iteration_and_resets(self):
        cur = BarHeightCurriculum()
        stepped = [cur.update_iteration(7.0) for _ in range(10)]
        # 7, 14, 21, 28, 35 > 30 → step at iteration 5, reset to 0; again at iteration 10
        assert stepped == [False] * 4 + [True] + [False] * 4 + [True]
        assert cur.level == 2 and cur.z == 0.52 and cur.accumulator == 0.0 and cur.iterations == 10
        cur.update_iteration(3.5)
        assert cur.accumulator == 3.5

    def test_threshold_must_be_exceeded_not_reached(self):
        cur = BarHeightCurriculum()
        assert [cur.update_iteration(10.0) for _ in range(4)] == [False, False, False, True]  # 30 is not > 30
        assert cur.z == 0.51

    def test_nan_or_missing_adds_nothing(self):
        cur = BarHeightCurriculum()
        for v in (float("nan"), None, math.inf, 12.0):
            cur.update_iteration(v)
        assert cur.accumulator == 12.0 and cur.iterations == 4

    def test_150_steps_land_exactly_on_z_max_then_cap(self):
        cur = BarHeightCurriculum()
        zs = []
        for _ in range(160):
            cur.update_iteration(31.0)  # a step every iteration
            zs.append(cur.z)
        assert zs[0] == 0.51 and zs[49] == 1.0 and zs[148] == 1.99 and zs[149] == 2.0
        assert zs[150:] == [2.0] * 10 and cur.at_max() and cur.level == 150
        assert cur.accumulator == 0.0  # the accumulator still resets at the cap
        assert all(round(z * 100) == pytest.approx(z * 100, abs=1e-9) for z in zs)  # whole centimetres

    def test_frozen_from_z_freeze(self):
        cur = BarHeightCurriculum()
        for _ in range(49):
            cur.update_iteration(31.0)
        assert cur.z == 0.99 and not cur.frozen()
        cur.update_iteration(31.0)
        assert cur.z == 1.0 and cur.frozen() and cur.state()["frozen"] == 1.0
        never = BarHeightCurriculum({"z_freeze": None})
        never.level = never.max_level
        assert not never.frozen()

    @pytest.mark.parametrize("rho, hz, c", [(0.0, 10.0, 48.0), (0.5, 20.0, 31.5), (1.0, 30.0, 15.0),
                                            (-0.7, 10.0, 48.0), (2.0, 30.0, 15.0)])
    def test_schedules(self, rho, hz, c):
        assert schedules.control_hz(rho) == pytest.approx(hz, abs=1e-12)
        assert schedules.c_offset(rho) == pytest.approx(c, abs=1e-12)

    @pytest.mark.parametrize("level, z, hz, c", [(0, 0.5, 10.0, 48.0), (25, 0.75, 20.0, 31.5),
                                                 (50, 1.0, 30.0, 15.0), (150, 2.0, 30.0, 15.0)])
    def test_high_jump_schedule_rho_is_2z_minus_1(self, level, z, hz, c):
        cur = BarHeightCurriculum()
        cur.load_state({"level": level, "accumulator": 0.0})
        assert cur.z == z and cur.rho == pytest.approx(2 * z - 1)
        assert cur.env_attrs() == pytest.approx({"bar_height": z, "control_hz": hz, "c_offset": c})

    def test_below_z_min_clips(self):
        cur = BarHeightCurriculum({"z_min": 0.3})  # ρ = −0.4 → the ρ = 0 values
        assert cur.env_attrs() == pytest.approx({"bar_height": 0.3, "control_hz": 10.0, "c_offset": 48.0})

    def test_signal_choice(self):
        items = reward_stream(3, 20.0)  # mean_return 20, mean_reward 1
        ret, rew = BarHeightCurriculum(), BarHeightCurriculum({"signal": "mean_reward"})
        for i, (eps, scalars, samples) in enumerate(items, 1):
            ret.on_iteration(i, samples, iteration_stats(scalars, eps))
            rew.on_iteration(i, samples, iteration_stats(scalars, eps))
        assert ret.level == 1 and ret.accumulator == 20.0  # 20, 40 > 30 → step, 20
        assert rew.level == 0 and rew.accumulator == 3.0 and rew.episodes == 12
        with pytest.raises(JtError, match="signal"):
            BarHeightCurriculum({"signal": "median"})


class TestObstacleWidth(CurriculumContract):
    cls, entry = ObstacleWidthCurriculum, "obstacle_width"

    def stream(self, n):
        return reward_stream(n, 12.0)  # 12·5 = 60 > 50: a step every 5 iterations

    def test_table1_defaults(self):
        cur = ObstacleWidthCurriculum()
        p = cur.params
        assert (p.z_min, p.z_max, p.dz, p.reward_threshold, p.z_freeze) == (0.05, 2.5, 0.05, 50.0, 1.0)
        assert cur.max_level == 49 and isinstance(cur, BarHeightCurriculum)

    def test_steps_and_cap(self):
        cur = ObstacleWidthCurriculum()
        assert [cur.update_iteration(25.0) for _ in range(3)] == [False, False, True]  # 50 is not > 50
        assert cur.z == 0.1
        for _ in range(100):
            cur.update_iteration(51.0)
        assert cur.z == 2.5 and cur.level == 49

    @pytest.mark.parametrize("level, z, hz, c", [(0, 0.05, 11.0, 46.35), (9, 0.5, 20.0, 31.5),
                                                 (19, 1.0, 30.0, 15.0), (49, 2.5, 30.0, 15.0)])
    def test_obstacle_schedule_rho_is_z_in_metres(self, level, z, hz, c):
        cur = ObstacleWidthCurriculum()
        cur.load_state({"level": level, "accumulator": 0.0})
        assert cur.z == z and cur.frozen() == (z >= 1.0)
        assert cur.env_attrs() == pytest.approx({"obstacle_width": z, "control_hz": hz, "c_offset": c})
