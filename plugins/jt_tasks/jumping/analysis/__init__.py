"""The analysis tools of the jump tasks (``JumpTask.studies``: ``task=highjump``, ``obstacle``,
``longjump``): ``jt study highjump`` lists them.

Nothing here runs during training; each module is a ``main(argv)`` that reads runs or files and
prints tables or draws figures (also ``python -m jt_tasks.jumping.analysis.<module>``).
"""
