"""The jumping tasks' shipped trained skills (``JumpTask.skills``): one folder each, holding its
``manifest.yaml``, its slim ``policy.h5`` and the ``prior.h5`` its actions decode through.
``jt play`` lists them, ``jt play NAME`` replays one (``toolkit.skills``, ``toolkit.play``)."""
