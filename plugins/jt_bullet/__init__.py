"""PyBullet plugins: characters (``jt_bullet.characters``), generated URDFs, simulator, scenes, and
everything of jt that reads or drives PyBullet: the ``toolkit.dynamics.Model`` of a body
(``model``), its state/torque I/O (``body``), the SPD benchmark (``bench``), mocap forward
kinematics (``kinematics``), rendering (``render``) and the SPD suite's worlds (``testing``).

Imports nothing heavy: pybullet is imported inside functions.
"""
