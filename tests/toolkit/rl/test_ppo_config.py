"""``PPOConfig``: a torch-free module, documented fields, one-line range errors."""

import ast
import dataclasses
import inspect
import math
import subprocess
import sys

import pytest

from toolkit.errors import JtError
from toolkit.rl import config as config_module
from toolkit.rl.config import PPOConfig, scheduled


def test_config_module_imports_no_torch_or_numpy():
    code = ("import sys, toolkit.rl.config as c; c.PPOConfig().check(); "
            "print(sorted(m for m in ('torch', 'numpy', 'h5py', 'toolkit.rl.ppo') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_ppo_and_package_re_export_the_same_class():
    import toolkit.rl
    from toolkit.rl import ppo

    assert ppo.PPOConfig is PPOConfig and toolkit.rl.PPOConfig is PPOConfig
    assert toolkit.rl.train is ppo.train


def test_every_field_has_a_docstring():
    tree = ast.parse(inspect.getsource(config_module))
    cls = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "PPOConfig")
    documented = set()
    for node, nxt in zip(cls.body, cls.body[1:]):
        if isinstance(node, ast.AnnAssign) and isinstance(nxt, ast.Expr) and isinstance(nxt.value, ast.Constant):
            assert len(nxt.value.value) > 20, node.target.id
            documented.add(node.target.id)
    assert documented == {f.name for f in dataclasses.fields(PPOConfig)}


def test_defaults_and_edge_values_pass():
    PPOConfig().check()
    PPOConfig(total_samples=0, std_anneal_samples=0, max_grad_norm=0.0, adv_clip=0.0, gamma=0.0, lam=1.0,
              target_kl=0.02, optimizer="adam").check()
    PPOConfig(total_samples=1e8, samples_per_iteration=4096.0, max_grad_norm=math.inf,
              std_schedule=[[0, 0.6], [2e7, 0.5]], lr_schedule=[(0, 1e-4, 1e-3), (2e7, 2e-5, 1e-3)]).check()


@pytest.mark.parametrize("changes, message", [
    ({"minibatch_size": 0}, "agent.minibatch_size=0: must be an integer >= 1"),
    ({"epochs": 2.5}, "agent.epochs=2.5: must be an integer >= 1"),
    ({"samples_per_iteration": 0}, "agent.samples_per_iteration=0: must be a whole number >= 1"),
    ({"total_samples": -1}, "agent.total_samples=-1: must be a whole number >= 0"),
    ({"total_samples": 1.5}, "agent.total_samples=1.5: must be a whole number >= 0"),
    ({"n_workers": 0}, "agent.n_workers=0: must be an integer >= 1"),
    ({"envs_per_worker": 0}, "agent.envs_per_worker=0: must be an integer >= 1"),
    ({"checkpoint_every": 0}, "agent.checkpoint_every=0: must be an integer >= 1"),
    ({"seed": -1}, "agent.seed=-1: must be an integer >= 0"),
    ({"clip": 0.0}, "agent.clip=0.0: must be a finite number > 0"),
    ({"policy_lr": -1e-4}, "agent.policy_lr=-0.0001: must be a finite number > 0"),
    ({"value_lr": math.inf}, "agent.value_lr=inf: must be a finite number > 0"),
    ({"std_start": 0.0}, "agent.std_start=0.0: must be a finite number > 0"),
    ({"std_end": math.nan}, "agent.std_end=nan: must be a finite number > 0"),
    ({"reward_scale": 0.0}, "agent.reward_scale=0.0: must be a finite number > 0"),
    ({"std_anneal_samples": -1.0}, "agent.std_anneal_samples=-1.0: must be a finite number >= 0"),
    ({"max_grad_norm": math.nan}, "agent.max_grad_norm=nan: must be a number >= 0 (0 disables)"),
    ({"gamma": 1.5}, "agent.gamma=1.5: must be in [0, 1]"),
    ({"lam": math.nan}, "agent.lam=nan: must be in [0, 1]"),
    ({"target_kl": 0.0}, "agent.target_kl=0.0: must be a number > 0, or null (always run every epoch)"),
    ({"optimizer": "rmsprop"}, "agent.optimizer=rmsprop: must be one of sgd, adam"),
    ({"policy_hidden": (64, 0)}, "agent.policy_hidden=[64, 0]: must be a list of layer sizes (integers >= 1)"),
    ({"reset_each_iteration": "no"}, "agent.reset_each_iteration=no: must be true or false"),
    ({"std_schedule": [[0, 0.6], [10, 0.0]]}, "agent.std_schedule[1]=[10, 0.0]: values must be finite numbers > 0"),
    ({"std_schedule": [[5, 0.6]]}, "agent.std_schedule[0]=[5, 0.6]: the first entry must start at 0 samples"),
    ({"std_schedule": [[0, 0.6], [0, 0.3]]}, "agent.std_schedule[1]=[0, 0.3]: sample counts must increase strictly"),
    ({"lr_schedule": [[0, 1e-4]]}, "agent.lr_schedule[0]=[0, 0.0001]: must be [samples, policy_lr, value_lr]"),
    ({"lr_schedule": 0.1},
     "agent.lr_schedule=0.1: must be a list of [samples, policy_lr, value_lr] entries (empty: off)"),
])
def test_check_names_key_value_and_range(changes, message):
    with pytest.raises(JtError) as e:
        dataclasses.replace(PPOConfig(), **changes).check()
    assert str(e.value) == message and "\n" not in str(e.value)


def test_check_prefix_and_train_refuses_a_bad_config():
    from toolkit.rl.ppo import train
    from toolkit.rl.sanity import GymEnvFn

    with pytest.raises(JtError, match=r"^ppo\.clip=-1: "):
        PPOConfig(clip=-1).check(prefix="ppo")
    with pytest.raises(JtError, match=r"^agent\.minibatch_size=0: "):
        train(GymEnvFn("Pendulum-v1"), PPOConfig(minibatch_size=0))


def test_scheduled_is_piecewise_constant():
    sched = [[0, 0.6], [100, 0.5], [200, 0.3]]
    assert scheduled(sched, 0) == (0.6,) and scheduled(sched, 99.9) == (0.6,)
    assert scheduled(sched, 100) == (0.5,) and scheduled(sched, 10**9) == (0.3,)
    assert scheduled([], 5) is None and scheduled([[10, 1.0]], 5) is None
    assert scheduled([[0, 1e-4, 1e-3], [50, 2e-5, 5e-4]], 60) == (2e-5, 5e-4)
