"""The contract test suites every plugin kind passes, shipped with jt (as Hydra ships
``hydra.test_utils``): jt's own tests and a third-party plugin's tests subclass the same classes.

* ``toolkit.testing.searcher.SearcherContract``: set ``searcher_cls``, ``cfg``, ``make_task()``.
* ``toolkit.testing.spd.SPDBackendSuite``: set ``backend_cls``.
* ``toolkit.testing.action.ActionSpaceContract``: define ``make()``.
* ``toolkit.testing.reward.RewardTermContract``: set ``cls``, ``entry``, ``record``, ``required``,
  ``cases``.
* ``toolkit.testing.curriculum.CurriculumContract``: set ``cls``, ``entry``, define ``stream(n)``.
* ``toolkit.testing.simulator.SimulatorContract``: define ``make()``.
* ``toolkit.testing.task.TaskContract``: set ``task``.
* ``toolkit.testing.executor.ExecutorContract``: set ``executor_cls``, ``entry`` (or override the
  ``executor`` fixture).

The modules import ``pytest`` (jt's ``test`` extra: ``pip install jt[test]``); import them from
test modules only. None imports a built-in plugin at module level. See docs/writing-a-plugin.md.
"""
