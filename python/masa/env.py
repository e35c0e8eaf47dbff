"""Tasks as batched environments with Gymnasium's vector API.

Every step runs the C++ tasks (the ones the actors train on) on OpenMP threads with the GIL
released, and hands back NumPy arrays the tasks wrote into directly: no copy per step. Episodes
that end are reset at once (Gymnasium's "same-step" autoreset, as masa's actors do); the ended
episode's last observation is in infos["final_obs"] (also "final_observation"), where
infos["_final_obs"] is True.

Seeds: reset(seed=s) restarts environment i from seed s + i, the seed masa_eval gives its
episode i, so a loop over a policy's actions replays masa_eval's episodes.
"""
import json
import os

import numpy as np

from . import _masa
from .spaces import Box, batch


def task_names():
    """The tasks of the catalog: one config per task in configs/tasks/ (YAML tasks included)."""
    folder = os.path.join(_masa.configs_dir(), "tasks")
    return sorted(f[:-len(".yaml")] for f in os.listdir(folder) if f.endswith(".yaml"))


def _override_strings(overrides):
    """{"env.max_episode_steps": 100} or ["env.max_episode_steps=100"] as the tools' --set strings."""
    if overrides is None:
        return []
    if isinstance(overrides, dict):
        return [f"{k}={v if isinstance(v, str) else json.dumps(v)}" for k, v in overrides.items()]
    if isinstance(overrides, str):
        return [overrides]
    return list(overrides)


def load_config(task=None, overrides=None, config_file=""):
    """The run configuration the tools build for `task` (configs/defaults.yaml, the task's file,
    then overrides), or from a run directory's config.yaml. Wrong names raise masa.ConfigError
    with masa_train's message."""
    sets = _override_strings(overrides)
    if task is not None:
        sets = [f"task={task}"] + sets
    if config_file and os.path.isdir(config_file):
        config_file = os.path.join(config_file, "config.yaml")
    return _masa.load_config(sets, str(config_file))


class VectorEnv:
    """num_envs instances of one masa task, stepped together (Gymnasium's VectorEnv API)."""

    metadata = {"render_modes": ["rgb_array"], "autoreset_mode": "SameStep"}

    def __init__(self, config, num_envs=1, seed=0, num_threads=None, spec=None, render_mode=None):
        if num_threads is None:
            num_threads = min(num_envs, os.cpu_count() or 1)
        self._env = (_masa.BatchedEnv(config, num_envs, num_threads) if spec is None
                     else _masa.BatchedEnv(config, spec, num_envs, num_threads))
        self.config = config
        self.num_envs = num_envs
        self.render_mode = render_mode
        self._seed = seed
        self._reset_once = False
        self.single_observation_space = Box(-np.inf, np.inf, (self._env.obs_dim,), np.float32)
        self.single_action_space = Box(-1.0, 1.0, (self._env.act_dim,), np.float32)
        self.observation_space = batch(self.single_observation_space, num_envs)
        self.action_space = batch(self.single_action_space, num_envs)
        for space in (self.single_action_space, self.action_space):  # sample() draws from make_env's seed
            if hasattr(space, "seed"):
                space.seed(seed)
        self.closed = False
        self._renderer = None

    # --- what the task is ---
    @property
    def task(self):
        return self._env.task

    @property
    def symmetry(self):
        """The task's symmetry (masa.Symmetry): its group and its transforms of rows."""
        return self._env.symmetry

    @property
    def reward_terms(self):
        return list(self._env.reward_terms)

    @property
    def max_episode_steps(self):
        return self._env.max_episode_steps

    @property
    def dt(self):
        """Seconds of simulated time per step."""
        return self._env.control_timestep

    @property
    def unwrapped(self):
        return self

    # --- Gymnasium's vector API ---
    def reset(self, *, seed=None, options=None):
        """Observations (num_envs, obs_dim) and an empty info dict. seed: environment i restarts
        from seed + i; None: the first reset uses make_env's seed, later ones go on from each
        environment's generator."""
        if seed is None and not self._reset_once:
            seed = self._seed
        self._reset_once = True
        obs = self._env.reset(None if seed is None else int(seed))
        return obs, {}

    def step(self, actions):
        """actions: (num_envs, act_dim) floats in [-1, 1] (float32 is used in place; float64 is
        converted). Returns observations, rewards (float64), terminated, truncated, infos."""
        if not self._reset_once:
            self.reset()
        (obs, reward, terminated, truncated, ended, final_obs, ep_return, ep_length,
         ep_success) = self._env.step(actions)
        infos = {}
        if ended.any():
            infos = {
                "final_obs": final_obs, "_final_obs": ended,
                "final_observation": final_obs, "_final_observation": ended,
                "episode": {"r": ep_return, "l": ep_length, "success": ep_success,
                            "_r": ended, "_l": ended, "_success": ended},
                "_episode": ended,
            }
        return obs, reward, terminated, truncated, infos

    def render(self, env_index=0, width=480, height=360):
        """Environment env_index as an RGB array (height, width, 3), uint8, seen by a camera that
        follows the robot (masa_eval's). Needs an OpenGL context: a display, or xvfb-run."""
        if self._renderer is None or tuple(self._renderer.size) != (width, height):
            self._renderer = _masa.Renderer(self._env, width, height)
        return self._renderer.frame(self._env, env_index)

    def close(self):
        self._renderer = None
        self.closed = True

    def __repr__(self):
        return f"masa.VectorEnv({self.task!r}, num_envs={self.num_envs})"

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def make_env(task, num_envs=1, seed=0, overrides=None, config_file="", num_threads=None, render_mode=None):
    """A batched environment of a catalog task (masa.task_names()), a run directory's task
    (task=None, config_file: its config.yaml or the directory), a masa.RunConfig, or a
    masa.Policy's own task (task=policy: the env section it was trained with).

    overrides: config keys as masa_train's --set takes them, {"env.max_episode_steps": 200}.
    num_threads: threads stepping the environments (default: the cores, at most num_envs).
    """
    from .policy import Policy
    if isinstance(task, Policy):
        return VectorEnv(task.config, num_envs, seed, num_threads, spec=task.symmetry, render_mode=render_mode)
    if isinstance(task, _masa.RunConfig):
        return VectorEnv(task, num_envs, seed, num_threads, render_mode=render_mode)
    if not isinstance(num_envs, int) or num_envs <= 0:
        raise ValueError(f"num_envs must be a positive integer, got {num_envs!r}")
    config = load_config(task, overrides, config_file)
    return VectorEnv(config, num_envs, seed, num_threads, render_mode=render_mode)
