"""Trained policies: a policy file loaded as masa_eval loads it, acting on batches."""
import os

from . import _masa


class Policy:
    """A masa policy: Policy.load(path) reads a policy file (or a run directory's policy.bin),
    checks its seal and, for MASA, its equivariance, as the tools do; act(obs) gives the policy
    mean for rows of raw observations (its normalizer included), tanh(mean) for a SAC policy."""

    def __init__(self, handle):
        self._p = handle

    @classmethod
    def load(cls, path):
        path = os.fspath(path)
        if os.path.isdir(path):
            path = os.path.join(path, "policy.bin")
        return cls(_masa.Policy.load(path))

    @classmethod
    def initial(cls, task, method="masa", seed=0, overrides=None):
        """An untrained policy of `method` for `task`, initialized as a run of that seed starts."""
        from .env import load_config, _override_strings
        sets = _override_strings(overrides) + [f"method={method}"]
        return cls(_masa.Policy.initial(load_config(task, sets), seed))

    def act(self, obs):
        """Actions (B, act_dim) float32 for observations (B, obs_dim) (or one row, (obs_dim,))."""
        return self._p.act(obs)

    __call__ = act

    def evaluate(self, episodes=20, seed=0, deterministic=True, max_steps=0, threads=1):
        """masa_eval's evaluation: episode k resets from seed + k. A dict of arrays per episode
        (return, length, terminated, success, terms, progress) and the printed summary."""
        return self._p.evaluate(episodes, seed, deterministic, max_steps, threads)

    def make_env(self, num_envs=1, seed=0, num_threads=None):
        """The policy's task as it was trained (its own env section and spec)."""
        from .env import make_env
        return make_env(self, num_envs=num_envs, seed=seed, num_threads=num_threads)

    source = property(lambda self: self._p.source)
    integrity = property(lambda self: self._p.integrity)
    task = property(lambda self: self._p.task)
    method = property(lambda self: self._p.method)
    config = property(lambda self: self._p.config)
    symmetry = property(lambda self: self._p.symmetry)
    symmetry_error = property(lambda self: self._p.symmetry_error)
    obs_dim = property(lambda self: self._p.obs_dim)
    act_dim = property(lambda self: self._p.act_dim)
    squashed = property(lambda self: self._p.squashed)

    def __repr__(self):
        return f"masa.Policy({self.task!r}, {self.method!r}, from {self.source!r})"
