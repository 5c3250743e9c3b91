"""The analysis tools of ``task=spacetime`` (``SpacetimeTask.studies``): ``jt study spacetime`` lists them.

Nothing here runs during training; each module is a ``main(argv)`` that reads runs or computes a
figure or table (also ``python -m jt_tasks.spacetime.analysis.<module>``).
"""
