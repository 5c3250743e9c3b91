"""``CharacterEnv``: the ``gymnasium.Env`` base of every policy task's environment.

It owns what all of them share: the simulator and the action space, both loaded through the
plugin registry from the spec's plain config (the env never names its simulator), the map from
an action to the PD targets of a control step, the step loop's bookkeeping, rendering and closing.
A subclass says only what its task is:

* ``setup()``: its scene and references (called once, after the character is loaded);
* ``start(options)``: put the character in an initial state for a new episode (may draw from
  ``self.np_random``); returns the reset ``info``;
* ``observe()``: the observation ``(obs_dim,)`` float32;
* ``watch``: the termination rules the simulator checks inside the substep loop (``Watch``);
* ``finish_step(rec)``: from the simulator's step record, ``(reward, terminated, truncated, info)``.

Optionally ``substeps_now()`` (fewer substeps in the last control step) and ``CAMERA`` (a
``toolkit.render.Camera``'s fields, ``None``: the simulator's view of the character).
"""

from __future__ import annotations

from typing import Any, ClassVar, Optional

import gymnasium
import numpy as np
from gymnasium import spaces

from toolkit.interfaces.simulator import Watch


def load_simulator(sim: dict) -> Any:
    """The simulator plugin for ``{"sim": ..., "spd": ..., "character": ...}`` (plain dicts), with
    its per-step contact summary off (policy envs declare the contacts they care about)."""
    from omegaconf import OmegaConf

    from toolkit import plugins

    cfg = OmegaConf.create(dict(sim))
    cfg.sim = OmegaConf.merge(cfg.get("sim") or {}, {"contacts": False})
    name = str(cfg.sim.get("name") or "") or plugins.sole("sim", "sim.name")  # a hand-written spec: the one installed
    return plugins.load("sim", name)(cfg)


class CharacterEnv(gymnasium.Env):
    """One simulated character driven through an action space at the control rate.

    Attributes:
        sim: the simulator plugin; ``sim_hz``, ``n_links``, ``masses`` ``(n_links + 1,)`` from it.
        control_hz: the control rate (Hz): the simulator's (``sim.control_hz``) unless the task's
            ``setup`` sets its own (the jumps' curriculum owns theirs).
        action_space_: the action-space plugin; ``skeleton`` its skeleton.
        watch: the termination rules of an episode (set by ``setup``).
        done: the episode has ended (``step`` then needs a ``reset``).
        penalty: the action space's ``penalty()`` of the last step's action.

    Args:
        spec: the task's picklable env spec; needs ``sim`` and ``action`` (plain config dicts).
        seed: seeds ``self.np_random``.
        render_mode: ``"rgb_array"``.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30}
    CAMERA: ClassVar[Optional[dict]] = None

    def __init__(self, spec: Any, seed: Optional[int] = None, render_mode: Optional[str] = "rgb_array") -> None:
        from toolkit import plugins

        super().__init__()
        self.spec_ = spec
        self.render_mode = render_mode
        self.sim = load_simulator(spec.sim)
        self.sim_hz = float(self.sim.sim_hz)
        self.control_hz = float(self.sim.control_hz)  # a task whose rate is its own sets it in setup()
        self.n_links = int(self.sim.n_links)
        self.masses = np.asarray(self.sim.masses)
        action = dict(spec.action)
        character = (dict(spec.sim).get("character") or {}).get("name")  # None: the action space's default
        self.action_space_ = plugins.load("action", str(action["name"]))(action, character)
        self.skeleton = self.action_space_.skeleton
        low, high = self.action_space_.bounds()
        scale = getattr(self.action_space_, "output_scale", None)
        self.policy_output_scale = scale() if scale is not None else None  # PPO's (toolkit.rl.networks)
        self.action_space = spaces.Box(np.asarray(low, np.float32), np.asarray(high, np.float32), dtype=np.float32)
        self.watch = Watch()
        self.done = False
        self.penalty = 1.0
        if seed is not None:
            self.np_random, _ = gymnasium.utils.seeding.np_random(int(seed))
        self.setup()
        self.action_space_.anchor(self.sim.state()[0])
        obs = self.observe()
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=obs.shape, dtype=np.float32)

    # ------------------------------------------------------------------ what a task writes
    def setup(self) -> None:
        """Build the scene and the references; set ``self.watch``; leave an initial state."""

    def start(self, options: Optional[dict]) -> dict:
        """Put the character in an initial state for a new episode; the reset ``info``."""
        raise NotImplementedError

    def observe(self) -> np.ndarray:
        """The observation ``(obs_dim,)`` float32."""
        raise NotImplementedError

    def finish_step(self, rec: dict[str, Any]) -> tuple[float, bool, bool, dict]:
        """``(reward, terminated, truncated, info)`` from the simulator's step record ``rec``."""
        raise NotImplementedError

    def substeps_now(self) -> Optional[int]:
        """Substeps of the next control step; None: the simulator's ``sim_hz / control_hz``."""
        return None

    def pd_velocity_targets(self) -> Optional[np.ndarray]:
        """``qd_target`` ``(n_dof,)`` of the next control step; None: zero target velocities."""
        return None

    # ------------------------------------------------------------------ shared machinery
    @staticmethod
    def flat(parts: Any) -> np.ndarray:
        """An observation ``(obs_dim,)`` float32 from its blocks (scalars, sequences, arrays of
        any shape), each flattened in order."""
        return np.concatenate([np.asarray(x, dtype=np.float64).reshape(-1) for x in parts]).astype(np.float32)

    @staticmethod
    def load_terms(terms: Any) -> dict[str, Any]:
        """``{name: jt.rewards term}`` built from ``{name: its parameters}`` through the registry."""
        from toolkit import plugins

        return {str(k): plugins.load("reward", str(k))(v) for k, v in dict(terms or {}).items()}

    @staticmethod
    def failure(rec: dict[str, Any]) -> str:
        """``"simulator: <why>"`` when the step record says the simulation failed (NaN, exploded
        state), else ``""``: one wording for every task's ``reason``."""
        return f"simulator: {rec['reason']}" if rec["failed"] else ""

    def links_and_com(self) -> tuple[np.ndarray, np.ndarray]:
        """Link centres of mass ``(n_links + 1, 3)`` (base first) and the CoM ``(3,)``."""
        pos, _ = self.sim.link_states()
        return pos, self.masses @ pos / self.masses.sum()

    def pd_targets(self, action: np.ndarray) -> np.ndarray:
        """``q_target`` ``(n_q,)`` of an action: the action space's joint targets, the root as now."""
        targets = self.action_space_.targets(np.asarray(action, dtype=np.float64))
        self.penalty = float(self.action_space_.penalty())
        q, _ = self.sim.state()
        return np.concatenate([q[:7], self.skeleton.dofs_to_joints(targets)])

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict] = None) -> tuple[np.ndarray, dict]:
        super().reset(seed=seed)
        self.done = False
        info = self.start(options)
        self.action_space_.anchor(self.sim.state()[0])  # action spaces relative to the start pose
        return self.observe(), info

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict]:
        if self.done:
            raise RuntimeError("step() after the episode ended; call reset()")
        q_target = self.pd_targets(action)
        rec = self.sim.step(q_target, self.pd_velocity_targets(), n_substeps=self.substeps_now(), watch=self.watch)
        reward, terminated, truncated, info = self.finish_step(rec)
        self.done = bool(terminated or truncated)
        obs = self.observe()
        if self.done:
            obs = np.nan_to_num(obs, nan=0.0, posinf=0.0, neginf=0.0)
        return obs, float(reward), bool(terminated), bool(truncated), info

    def render(self) -> np.ndarray:
        """RGB frame ``(240, 320, 3)`` uint8."""
        return self.render_frame(320, 240)

    def render_frame(self, width: int, height: int, mask: bool = False) -> Any:
        """RGB frame ``(height, width, 3)`` uint8 (the class's ``CAMERA``, else the simulator's
        view); with ``mask``, ``(frame, character pixels (height, width) bool)``."""
        from toolkit.render import Camera

        return self.sim.render(width, height, Camera(**self.CAMERA) if self.CAMERA else None, mask=mask)

    def close(self) -> None:
        if getattr(self, "sim", None) is not None:
            self.sim.close()
            self.sim = None
