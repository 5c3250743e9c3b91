"""Plugin interfaces: abstract base classes and the small dataclasses they exchange.

Nothing here imports numpy, torch, pybullet or mlflow at module level, so any module may import
these cheaply. Implementations live in ``plugins/`` (built-ins) or in third-party packages; every
one is found through an entry point in the group named in ``toolkit.plugins.KINDS``.
"""

from toolkit.interfaces.action import ActionSpace
from toolkit.interfaces.curriculum import Curriculum
from toolkit.interfaces.executor import ActorGroup, Executor, ExecutorKeys
from toolkit.interfaces.plugin import Plugin
from toolkit.interfaces.reward import RewardTerm
from toolkit.interfaces.searcher import Param, SearchProblem, Searcher, Space
from toolkit.interfaces.simulator import BASE, ContactRule, Simulator, Watch
from toolkit.interfaces.spd import SPDBackend
from toolkit.interfaces.task import EvalContext, Evaluation, Task

__all__ = [
    "BASE",
    "ContactRule",
    "Watch",
    "ActionSpace",
    "ActorGroup",
    "Curriculum",
    "EvalContext",
    "Evaluation",
    "Executor",
    "ExecutorKeys",
    "Param",
    "Plugin",
    "RewardTerm",
    "SPDBackend",
    "SearchProblem",
    "Searcher",
    "Simulator",
    "Space",
    "Task",
]
