"""The spacetime task's shipped trained skills (``SpacetimeTask.skills``): the walk and run of
``experiment=laptop``, one folder each holding its ``manifest.yaml`` and slim ``policy.h5``.
``jt play walk`` replays one (``toolkit.skills``, ``toolkit.play``)."""
