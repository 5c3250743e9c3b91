"""Difficulty-driven schedules of ``000`` §6.1.3 (thesis ``001`` §3.6.1 "Curriculum and Scheduling").

``f_control = 10 + 20·Clip(ρ, 0, 1)`` Hz and ``c_offset = 48 − 33·Clip(ρ, 0, 1)``, where
``ρ = 2z − 1`` for high jumps and ``ρ = z`` for obstacle jumps, ``z`` in metres (the bar height or
the obstacle width): both reach their end values at ``z = 1 m`` = ``z_freeze``.
"""

from __future__ import annotations


def clip01(x: float) -> float:
    """``Clip(x, 0, 1)``."""
    return min(max(float(x), 0.0), 1.0)


def progress(z: float, scale: float = 2.0, offset: float = -1.0) -> float:
    """``ρ = scale·z + offset`` (unclipped): ``(2, −1)`` high jump, ``(1, 0)`` obstacle jump."""
    return scale * float(z) + offset


def control_hz(rho: float, start: float = 10.0, span: float = 20.0) -> float:
    """``f_control = start + span·Clip(ρ, 0, 1)`` in Hz (``000`` §6.1.3: 10 → 30 Hz)."""
    return start + span * clip01(rho)


def c_offset(rho: float, start: float = 48.0, span: float = 33.0) -> float:
    """``c_offset = start − span·Clip(ρ, 0, 1)`` (``000`` §6.1.3: 48 → 15; eq 4's denominator)."""
    return start - span * clip01(rho)
