"""The adaptive task-difficulty curriculum of ``000`` §6.1.3 and Table 1 (thesis ``001`` §3.6.1).

"At each training iteration, the average sample reward is added to a reward accumulator. We
increase z by Δz whenever the accumulated reward exceeds a threshold R_T, and then reset the
reward accumulator." The control rate and the P-VAE offset-penalty coefficient follow ``z``
(``schedules``), and training for strategy discovery stops at ``z_freeze = 100 cm``.

``z`` is kept as an integer level ``k`` (``z = min(z_min + k·Δz, z_max)``), so that 150 steps
of 1 cm land exactly on 2.0 m and a saved state restores bit-identically.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Optional

from jt_curricula import schedules
from jt_curricula.base import IterationCurriculum, finite_or
from toolkit.errors import JtError

_TOL = 1e-9


class BarHeightCurriculum(IterationCurriculum):
    """High-jump bar height z: +Δz each time the accumulated iteration reward exceeds R_T (000 §6.1.3)."""

    @dataclasses.dataclass
    class Config:
        z_min: float = 0.5
        """50 cm (000 Table 1)."""
        z_max: float = 2.0
        """200 cm (000 Table 1)."""
        dz: float = 0.01
        """Δz = 1 cm (000 Table 1)."""
        reward_threshold: float = 30.0
        """R_T (000 Table 1)."""
        z_freeze: Optional[float] = 1.0
        """Strategy discovery stops at 100 cm; null = train to z_max (000 §6.1.4)."""
        rho_scale: float = 2.0
        """Ρ = 2z − 1 for high jumps (000 §6.1.3)."""
        rho_offset: float = -1.0
        """(000 §6.1.3)."""
        control_hz_start: float = 10.0
        """F_control = 10 + 20·Clip(ρ, 0, 1) Hz (000 §6.1.3)."""
        control_hz_span: float = 20.0
        """(000 §6.1.3)."""
        c_offset_start: float = 48.0
        """C_offset = 48 − 33·Clip(ρ, 0, 1) (000 §6.1.3, eq 4)."""
        c_offset_span: float = 33.0
        """(000 §6.1.3)."""
        signal: str = "mean_return"
        """Accumulated stat: mean episode return of the iteration (jt reading of "average sample reward", see docs)."""
        z_attr: str = "bar_height"
        """Environment attribute receiving z (jt)."""

        def check(self) -> None:
            """Finite values, dz > 0, z_min <= z_freeze <= z_max, R_T >= 0, a known signal (one
            ``JtError`` line, at composition)."""
            from toolkit.schema import finite, require

            for key in ("z_min", "z_max", "dz", "reward_threshold", "rho_scale", "rho_offset",
                        "control_hz_start", "control_hz_span", "c_offset_start", "c_offset_span"):
                require(finite(getattr(self, key)), f"curriculum.{key}", getattr(self, key), "must be a finite number")
            require(self.dz > 0, "curriculum.dz", self.dz, "must be > 0")
            require(self.z_min >= 0, "curriculum.z_min", self.z_min, "must be >= 0")
            require(self.z_max >= self.z_min, "curriculum.z_max", self.z_max, f"must be >= z_min = {self.z_min}")
            if self.z_freeze is not None:
                require(finite(self.z_freeze) and self.z_min <= self.z_freeze <= self.z_max, "curriculum.z_freeze",
                        self.z_freeze, f"must lie in [z_min, z_max] = [{self.z_min}, {self.z_max}] (or null)")
            require(self.reward_threshold >= 0, "curriculum.reward_threshold", self.reward_threshold, "must be >= 0")
            require(self.control_hz_start > 0 and self.control_hz_start + self.control_hz_span > 0,
                    "curriculum.control_hz_start", self.control_hz_start, "control rates must stay > 0")
            require(self.signal in ("mean_return", "mean_reward"), "curriculum.signal", self.signal,
                    "mean_return or mean_reward")

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        p = self.params
        self.max_level = max(0, math.ceil((p.z_max - p.z_min) / p.dz - _TOL))
        self.level = 0
        self.accumulator = 0.0
        self.iterations = 0
        self.episodes = 0

    # ---------------------------------------------------------------- difficulty and schedules

    @property
    def z(self) -> float:
        """Current difficulty z (m): the bar height (or obstacle width)."""
        p = self.params
        return round(min(p.z_min + self.level * p.dz, p.z_max), 9)

    @property
    def rho(self) -> float:
        """``ρ`` of the schedules (unclipped)."""
        return schedules.progress(self.z, self.params.rho_scale, self.params.rho_offset)

    def control_hz(self) -> float:
        """Control rate ``f_control`` (Hz) at the current z."""
        return schedules.control_hz(self.rho, self.params.control_hz_start, self.params.control_hz_span)

    def c_offset(self) -> float:
        """Offset-penalty coefficient ``c_offset`` (``000`` eq 4) at the current z."""
        return schedules.c_offset(self.rho, self.params.c_offset_start, self.params.c_offset_span)

    def env_attrs(self) -> dict[str, Any]:
        """``{z_attr: z, "control_hz": f_control, "c_offset": c_offset}`` for every environment."""
        return {self.params.z_attr: self.z, "control_hz": self.control_hz(), "c_offset": self.c_offset()}

    def at_max(self) -> bool:
        """True when z has reached ``z_max``."""
        return self.level >= self.max_level

    def frozen(self) -> bool:
        """True once z has reached ``z_freeze`` (strategy discovery stops training there)."""
        zf = self.params.z_freeze
        return zf is not None and self.z >= zf - _TOL

    # ---------------------------------------------------------------- updates

    def update(self, episode: dict[str, Any]) -> None:
        """Count a finished episode (the accumulator itself is fed once per iteration)."""
        self.episodes += 1

    def update_iteration(self, value: float) -> bool:
        """Add one iteration's average reward to the accumulator; step z when it exceeds R_T.

        Args:
            value: the iteration's average reward (NaN / None, e.g. no episode ended, adds 0).

        Returns:
            True when z was increased by this call.
        """
        self.iterations += 1
        self.accumulator += finite_or(value)
        if self.accumulator > self.params.reward_threshold:
            self.accumulator = 0.0
            if not self.at_max():
                self.level += 1
                return True
        return False

    def end_iteration(self, iteration: int, samples: int, stats: Any) -> None:
        """Feed ``stats[signal]`` to ``update_iteration``."""
        self.update_iteration(stats.get(self.params.signal) if hasattr(stats, "get") else stats)

    # ---------------------------------------------------------------- state

    def state(self) -> dict[str, float]:
        """``z``, ``level``, ``accumulator``, ``iterations``, ``episodes`` and the scheduled values."""
        return {"z": self.z, "level": self.level, "accumulator": self.accumulator,
                "iterations": self.iterations, "episodes": self.episodes,
                "control_hz": self.control_hz(), "c_offset": self.c_offset(),
                "frozen": float(self.frozen())}

    def load_state(self, state: dict[str, float]) -> None:
        """Restore a ``state()`` (the derived entries are recomputed, not read)."""
        level = int(round(float(state["level"])))
        if not 0 <= level <= self.max_level:
            raise ValueError(f"{type(self).__name__}: saved level {level} outside [0, {self.max_level}]")
        self.level = level
        self.accumulator = float(state["accumulator"])
        self.iterations = int(state.get("iterations", 0))
        self.episodes = int(state.get("episodes", 0))


class ObstacleWidthCurriculum(BarHeightCurriculum):
    """Obstacle-jump width z: +Δz each time the accumulated iteration reward exceeds R_T (000 §6.1.3)."""

    @dataclasses.dataclass
    class Config(BarHeightCurriculum.Config):
        z_min: float = 0.05  # starting obstacle width, m (000 Table 1: 5 cm)
        z_max: float = 2.5  # widest obstacle, m (000 Table 1: 250 cm)
        dz: float = 0.05  # increment Δz, m (000 Table 1: 5 cm)
        reward_threshold: float = 50.0  # accumulated-reward threshold R_T (000 Table 1)
        rho_scale: float = 1.0  # obstacle jump ρ = z, z in m (000 §6.1.3)
        rho_offset: float = 0.0  # see rho_scale (000 §6.1.3)
        z_attr: str = "obstacle_width"  # environment attribute that receives z
