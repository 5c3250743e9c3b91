"""What every humanoid environment of jt's tasks sets up the same way: simulator, body, action space.

``JumpEnv`` (``jumping/env.py``) and ``RunupEnv`` (``runup/env.py``) both drive the ``bullet``
simulator plugin one substep at a time with its own contact checks switched off (they check the
contacts they care about), and map actions to PD targets through an action-space plugin.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def setup_character(env: Any, sim: dict, action: dict) -> None:
    """Give ``env`` its simulator and action space, both loaded through the plugin registry.

    Sets ``sim``, ``client``, ``body``, ``ground``, ``sim_hz``, ``n_links``, ``masses`` ``(n_links + 1,)``
    (base first), ``action_space_`` (the plugin), ``skeleton`` and the gymnasium ``action_space``.

    Args:
        env: the environment being built.
        sim: ``{"sim": ..., "spd": ..., "character": ...}`` config nodes as plain dicts.
        action: the action group (``{"name": "raw", ...}``).
    """
    import pybullet as pb
    from gymnasium import spaces
    from omegaconf import OmegaConf

    from toolkit import plugins

    sim_cfg = OmegaConf.create(dict(sim))
    sim_cfg.sim = OmegaConf.merge(sim_cfg.get("sim") or {}, {"contacts": False})
    sim_name = str((sim_cfg.sim.get("name") if "name" in sim_cfg.sim else None) or "bullet")
    env.sim = plugins.load("sim", sim_name)(sim_cfg)
    env.client = env.sim.client
    env.body = env.sim.character.body_id
    env.ground = int(getattr(env.sim, "ground_id", -1))
    env.sim_hz = float(env.sim.params.sim_hz)
    env.sim.n_substeps = 1
    env.n_links = pb.getNumJoints(env.body, physicsClientId=env.client)
    env.masses = np.array([pb.getDynamicsInfo(env.body, i, physicsClientId=env.client)[0]
                           for i in range(-1, env.n_links)])
    act_cfg = OmegaConf.create(dict(action))
    env.action_space_ = plugins.load("action", str(act_cfg.name))(act_cfg, "humanoid")
    env.skeleton = env.action_space_.skeleton
    low, high = env.action_space_.bounds()
    env.action_space = spaces.Box(np.asarray(low, np.float32), np.asarray(high, np.float32), dtype=np.float32)
