"""Reward terms of the athletic-jumping papers (``jt.rewards``).

A task's reward is the product of its configured terms (``000`` eqs 2, 15, 16); each term is a
pure function of the task's episode record. See ``docs/rewards_curricula.md``.
"""
