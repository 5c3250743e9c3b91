"""Built-in SPD backends (``jt.spd``): maba, df, sf, pcg (``toolkit.dynamics``) and bullet.

Imports nothing heavy: numba/pybullet load when a backend is bound.
"""
