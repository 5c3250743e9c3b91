"""The shared layer of jt's policy-learning tasks (jumps, run-up, spacetime bounds, get-up).

``env.CharacterEnv``: a ``gymnasium.Env`` of one simulated character (simulator and action space
from the registry, the substep loop and its termination rules in the simulator).
``task.PolicyTask``: a ``Task`` whose evaluation trains PPO on such an env, rolls the deterministic
policy out and writes its artifacts (``ppo.h5``, ``rollout.h5``, filmstrip and GIF) and curves.
``episodes.rollout``: one deterministic episode (a typed ``Rollout``), ``episodes.opened_env`` an
env closed however its block ends; ``periodic.PeriodicEvaluation``: an evaluation every few PPO
iterations, kept in ``ppo.h5``; ``history``: per-iteration curves and the metrics every task reports;
``trained``: a policy trained earlier (``task.evaluate=NAME|RUN|PATH``), resolved, checked and measured
instead of trained.
A new policy task writes only what is its own: scene, initial states, observation, termination
rules, reward and metrics (docs/writing-a-plugin.md).
"""
