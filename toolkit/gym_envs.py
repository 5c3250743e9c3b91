"""jt's RL tasks as Gymnasium environments, for training them with other RL libraries.

Every task plugin whose class overrides ``Task.make_env`` is registered as ``jt/<task>-v0`` when
this module is imported; Gymnasium's ``"module:env_id"`` form imports it for you::

    import gymnasium
    env = gymnasium.make("toolkit.gym_envs:jt/highjump-v0", overrides=["action=raw"])
    env = gymnasium.make("toolkit.gym_envs:jt/runup-v0", point={"omega_x": -2.0}, seed=3)

``overrides`` are the same Hydra overrides ``jt run`` takes (``action=pvae action.prior=RUN_ID``,
``task.v_y=null``, ``curriculum.z_min=0.8`` ...); ``point`` sets the task's searched parameters
(take-off features); the environment is the one jt's own PPO trains on. Third-party task plugins
are registered the same way.
"""

from __future__ import annotations

from typing import Any, Optional, Sequence

NAMESPACE = "jt"


def make(task: str, overrides: Sequence[str] = (), point: Optional[dict] = None,
         seed: Optional[int] = None, **_: Any) -> Any:
    """The task's environment from a composed jt config (Gymnasium's entry point for ``jt/<task>-v0``)."""
    from toolkit import plugins
    from toolkit.config import compose, validate

    cfg = validate(compose([f"task={task}", *overrides]))
    return plugins.load("task", task)(cfg).make_env(point, seed)


def env_tasks() -> list[str]:
    """Names of the task plugins that provide an environment (their class overrides ``make_env``)."""
    from toolkit import plugins
    from toolkit.interfaces.task import Task

    out = []
    for name in plugins.names("task"):
        try:
            cls = plugins.load("task", name)
        except Exception:  # noqa: BLE001 - a broken plugin is listed by `jt plugins`, not here
            continue
        if getattr(cls, "make_env", Task.make_env) is not Task.make_env:
            out.append(name)
    return out


def register_all() -> list[str]:
    """Register ``jt/<task>-v0`` for every task with an environment; returns the ids."""
    import gymnasium

    ids = []
    for name in env_tasks():
        env_id = f"{NAMESPACE}/{name}-v0"
        if env_id not in gymnasium.registry:
            gymnasium.register(env_id, entry_point="toolkit.gym_envs:make", kwargs={"task": name},
                               disable_env_checker=True)
        ids.append(env_id)
    return ids


register_all()
