"""The terrain curriculum of the get-up paper (``003`` §5.4).

"The same terrain is used for all experiments, but it is divided into four regions (flat, easy,
medium, and hard difficulties). The agent is first trained on the flat region and must succeed in
getting-up 200 times to unlock the next region. The agent revisits all unlocked regions during
training in order to avoid catastrophic forgetting." The ablations of ``003`` §6.4 instead unlock
a region every 20 M simulation steps (``fixed_every_samples``).
"""

from __future__ import annotations

import dataclasses
from typing import Any

from jt_curricula.base import IterationCurriculum
from toolkit.errors import JtError


class TerrainCurriculum(IterationCurriculum):
    """Get-up terrain regions flat → easy → medium → hard, each unlocked by 200 successes (003 §5.4)."""

    @dataclasses.dataclass
    class Config:
        regions: list[str] = dataclasses.field(
            default_factory=lambda: ["flat", "easy", "medium", "hard"])
        """Four regions in order of difficulty (003 §5.4, Fig. 3)."""
        successes_to_unlock: int = 200
        """Successes needed to unlock the next region (003 §5.4)."""
        frontier_only: bool = True
        """Count successes on the newest region only (jt; 003 does not say)."""
        fixed_every_samples: int = 0
        """0 = adaptive; 20000000 = the fixed schedule of 003's ablations (003 §6.4)."""
        success_key: str = "success"
        """Episode key of the success flag (jt)."""
        region_key: str = "terrain_level"
        """Episode key of the region an episode ran on (jt)."""
        level_attr: str = "terrain_level"
        """Environment attribute: highest unlocked region; envs sample 0..level (jt; 003 §5.4 "revisits all unlocked regions")."""

        def check(self) -> None:
            """One ``JtError`` line at composition: regions named, once each; counts in range."""
            from toolkit.schema import require

            require(bool(self.regions) and len(set(self.regions)) == len(self.regions), "curriculum.regions",
                    list(self.regions), "one or more region names, each once")
            require(int(self.successes_to_unlock) >= 1, "curriculum.successes_to_unlock", self.successes_to_unlock,
                    "must be >= 1")
            require(int(self.fixed_every_samples) >= 0, "curriculum.fixed_every_samples", self.fixed_every_samples,
                    "must be >= 0 (0: adaptive)")

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        p = self.params
        if not p.regions or p.successes_to_unlock < 1 or p.fixed_every_samples < 0:
            raise JtError(f"terrain: need regions, successes_to_unlock >= 1, fixed_every_samples >= 0; got {p}")
        self.level = 0  # highest unlocked region index; regions 0..level are all in use
        self.successes = 0  # successes counted towards the next unlock
        self.episodes = 0

    @property
    def max_level(self) -> int:
        return len(self.params.regions) - 1

    def region(self) -> str:
        """Name of the newest unlocked region."""
        return self.params.regions[self.level]

    def env_attrs(self) -> dict[str, Any]:
        """``{level_attr: level}``: the environment samples its start among regions ``0..level``."""
        return {self.params.level_attr: self.level}

    def _unlock(self) -> None:
        if self.level < self.max_level:
            self.level += 1
        self.successes = 0

    def update(self, episode: dict[str, Any]) -> None:
        """Count a successful episode (on the frontier region when ``frontier_only`` and the
        episode says where it ran); unlock the next region at ``successes_to_unlock``."""
        p = self.params
        self.episodes += 1
        if p.fixed_every_samples or not bool(episode.get(p.success_key, False)):
            return
        where = episode.get(p.region_key)
        if p.frontier_only and where is not None and int(round(float(where))) != self.level:
            return
        self.successes += 1
        if self.successes >= p.successes_to_unlock and self.level < self.max_level:
            self._unlock()

    def end_iteration(self, iteration: int, samples: int, stats: Any) -> None:
        """With ``fixed_every_samples``: unlock ``samples // fixed_every_samples`` regions."""
        every = self.params.fixed_every_samples
        if every:
            self.level = min(int(samples) // every, self.max_level)

    def state(self) -> dict[str, float]:
        """``level`` (highest unlocked region), ``successes`` towards the next, ``episodes``."""
        return {"level": self.level, "successes": self.successes, "episodes": self.episodes}

    def load_state(self, state: dict[str, float]) -> None:
        level = int(round(float(state["level"])))
        if not 0 <= level <= self.max_level:
            raise ValueError(f"terrain: saved level {level} outside [0, {self.max_level}]")
        self.level = level
        self.successes = int(state["successes"])
        self.episodes = int(state.get("episodes", 0))
