"""Curricula of the athletic-jumping and get-up papers (``jt.curricula``).

``bar_height`` / ``obstacle_width``: the adaptive reward-accumulator curriculum with the control
rate and offset-penalty schedules of ``000`` §6.1.3 (Table 1). ``terrain``: the unlock-by-success
terrain curriculum of ``003`` §5.4. See ``docs/rewards_curricula.md``.
"""
