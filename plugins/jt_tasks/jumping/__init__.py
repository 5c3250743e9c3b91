"""``task=highjump|obstacle|longjump`` (000 §5-§6): modules takeoff, scene, env, features, train, task, stage2.

Nothing heavy is imported here (PyBullet, torch and gymnasium load inside the modules that use them).
"""
