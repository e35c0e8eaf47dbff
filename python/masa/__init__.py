"""masa from Python: the tasks as batched environments, their symmetries, policies and runs.

    import masa
    env = masa.make_env("a1_beam", num_envs=64)
    obs, infos = env.reset(seed=0)
    obs, rewards, terminated, truncated, infos = env.step(actions)

The work is done by masa's C++ libraries (the extension module masa._masa); docs/python.md has
the examples.
"""
from ._masa import ConfigError, RunConfig, Symmetry
from .env import VectorEnv, make_env, task_names, load_config
from .policy import Policy
from .symmetry import symmetry, check_equivariance, EquivarianceError
from .runs import Run, train, read_dataset
from . import spaces
from ._gymnasium import register_with_gymnasium

__all__ = [
    "ConfigError", "RunConfig", "Symmetry", "VectorEnv", "make_env", "task_names", "load_config", "Policy",
    "symmetry", "check_equivariance", "EquivarianceError", "Run", "train", "read_dataset", "spaces",
]

register_with_gymnasium()
