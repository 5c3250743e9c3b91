"""PyBullet plugins: characters (``jt_bullet.characters``), generated URDFs, simulator, scenes.

Imports nothing heavy: pybullet is imported inside functions.
"""
