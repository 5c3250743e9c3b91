"""Take-off states (``000`` §3, §6.1.1), shared by the jump tasks and the run-up task.

* ``state``: the ``TakeoffState`` dataclass and its construction from a frame of the run clip with
  imposed features (``takeoff_state``, ``impose``, ``heading_quat``, ``FOOT_LINKS``, ...);
* ``state_file``: the ``takeoff_state.h5`` file a run-up controller writes;
* ``source``: ``task.takeoff_from``, finding and loading such a file for a jump.

Neither ``jt_tasks.jumping`` nor ``jt_tasks.runup`` is imported here: both import this package.
Nothing heavy is imported at package level.
"""
