"""``task=standing_jump``: Pareto-optimal natural and supernatural standing jumps (``004``).

Modules: ``model`` (17-link planar humanoid, URDF), ``kinematics`` (planar forward kinematics),
``params`` (the 34 searched parameters), ``controller`` (finite-state machine, PD, virtual force,
foot-placement IK), ``simulate`` (one PyBullet episode), ``objectives`` (eqs 1–6, fronts,
hypervolume), ``render`` (filmstrips, front plot), ``summary`` (Tables 2–3, Fig. 8), ``task``.
Nothing heavy is imported here: PyBullet and matplotlib load inside the functions that use them.
"""

from jt_tasks.standing_jump.task import StandingJumpTask

__all__ = ["StandingJumpTask"]
