"""The minimal policy task of docs/writing-a-plugin.md, verbatim (but for its module path)."""

import dataclasses
import numpy as np
from toolkit.policy.env import CharacterEnv
from toolkit.policy.spec import spec_of
from toolkit.policy.task import PolicyConfig, PolicyTask
from toolkit.interfaces import ContactRule, Watch

@dataclasses.dataclass
class StandConfig(PolicyConfig):     # filmstrip_frames, _width, _height come from PolicyConfig
    name: str = "stand"
    """Registry name."""
    time_limit: float = 5.0
    """s of standing asked for (ours)."""

@dataclasses.dataclass
class StandSpec(StandConfig):         # picklable: rollout workers rebuild the env from it
    sim: dict = dataclasses.field(default_factory=dict)     # every task.* setting inherited,
    action: dict = dataclasses.field(default_factory=dict)  # plus what the task resolves

class StandEnv(CharacterEnv):
    FEET = ("right_ankle", "left_ankle")  # the humanoid's ankle links, by name

    def setup(self):                  # scene + termination rules, checked inside the 600 Hz loop
        feet = tuple(self.sim.link_index(n) for n in self.FEET)  # names -> indices, once
        self.watch = Watch(rules=(ContactRule(self.sim.ground, "fail", "fell", except_links=feet),),
                           time_limit=self.spec_.time_limit, time_limit_outcome="truncate")
        self.q0, self.qd0 = self.sim.state()

    def start(self, options):         # an initial state per episode
        self.sim.reset(self.q0, self.qd0)
        return {}

    def observe(self):
        q, qd = self.sim.state()
        return np.concatenate([q, qd]).astype(np.float32)

    def finish_step(self, rec):       # reward, terminated, truncated, info from the step record
        fell = rec["outcome"] == "fail"
        return (0.0 if fell else 1.0), fell, rec["outcome"] == "truncate", {"reason": rec["reason"]}

class StandTask(PolicyTask):
    """Stay up: a minimal policy task."""
    Config = StandConfig
    env_path = "stand_example:StandEnv"

    def env_spec(self, point):
        sim, action = self.character_groups()      # sim, spd, character, action groups as dicts
        return spec_of(StandSpec, self.params, sim=sim, action=action)  # the Config's fields copied
