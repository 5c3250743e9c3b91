"""The analysis tools of ``task=standing_jump`` (``StandingJumpTask.studies``): ``jt study standing_jump``
lists them.

Nothing here runs during a search; each module is a ``main(argv)`` that measures or compares and
prints tables or draws figures (also ``python -m jt_tasks.standing_jump.analysis.<module>``).
"""
