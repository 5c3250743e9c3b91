"""``task=runup``: DeepMimic run-up controllers that end in a desired take-off state (``000`` §6.1.1)."""
