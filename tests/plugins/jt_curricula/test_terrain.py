"""terrain: regions unlocked after 200 successful get-ups (003 §5.4), or on a fixed schedule (§6.4)."""

from __future__ import annotations

import pytest

from toolkit.testing.curriculum import CurriculumContract
from jt_curricula.terrain import TerrainCurriculum


def ok(level=None):
    ep = {"return": 1.0, "length": 100.0, "terminated": 0.0, "success": 1.0}
    if level is not None:
        ep["terrain_level"] = float(level)
    return ep


FAIL = {"return": 0.1, "length": 30.0, "terminated": 1.0, "success": 0.0}


class TestTerrain(CurriculumContract):
    cls, entry = TerrainCurriculum, "terrain"
    n_iterations = 60

    def stream(self, n):
        # 9 episodes per iteration, 7 of them successful on no particular region
        eps = [ok()] * 7 + [FAIL] * 2
        return [(eps, {"mean_return": 0.8}, 1000 * (i + 1)) for i in range(n)]

    def test_paper_defaults(self):
        p = TerrainCurriculum().params
        assert p.regions == ["flat", "easy", "medium", "hard"] and p.successes_to_unlock == 200

    def test_200_successes_unlock_the_next_region(self):
        cur = TerrainCurriculum()
        for _ in range(199):
            cur.update(ok(0))
            cur.update(FAIL)
        assert cur.level == 0 and cur.successes == 199 and cur.region() == "flat"
        cur.update(ok(0))
        assert cur.level == 1 and cur.successes == 0 and cur.region() == "easy"
        assert cur.env_attrs() == {"terrain_level": 1} and cur.episodes == 399

    def test_frontier_only_counts_the_newest_region(self):
        cur = TerrainCurriculum()
        cur.load_state({"level": 1, "successes": 0})
        for _ in range(300):
            cur.update(ok(0))  # revisiting flat does not unlock medium
        assert cur.level == 1 and cur.successes == 0
        for _ in range(200):
            cur.update(ok(1))
        assert cur.level == 2
        anywhere = TerrainCurriculum({"frontier_only": False})
        anywhere.load_state({"level": 1, "successes": 0})
        for _ in range(200):
            anywhere.update(ok(0))
        assert anywhere.level == 2

    def test_caps_at_the_hardest_region(self):
        cur = TerrainCurriculum({"successes_to_unlock": 2})
        for _ in range(20):
            cur.update(ok())
        assert cur.level == 3 and cur.region() == "hard"

    @pytest.mark.parametrize("samples, level", [(19_999_999, 0), (20_000_000, 1), (60_000_000, 3), (10**9, 3)])
    def test_fixed_schedule_of_the_ablations(self, samples, level):
        cur = TerrainCurriculum({"fixed_every_samples": 20_000_000})
        for _ in range(500):
            cur.update(ok())  # ignored on the fixed schedule
        cur.end_iteration(1, samples, {})
        assert cur.level == level
