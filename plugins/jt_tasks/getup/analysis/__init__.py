"""The analysis tools of ``task=getup`` (``GetupTask.studies``): ``jt study getup`` lists them.

Nothing here runs during training; each module is a ``main(argv)`` that reads runs or files and
prints tables or draws figures (also ``python -m jt_tasks.getup.analysis.<module>``).
"""
