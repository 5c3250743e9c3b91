"""``task=highjump|obstacle|longjump`` (000 §5-§6): modules scene, env, features, train, task, stage2.

The take-off state they start from lives in ``jt_tasks.takeoff`` (shared with ``task=runup``).

Nothing heavy is imported here (PyBullet, torch and gymnasium load inside the modules that use them).
"""
