"""Runs from Python: start one with the tools' own launchers (masa_train, or deploy/train.sh), one
call, and read a run directory back: its resolved config, its metrics as arrays, its policy."""
import os
import shutil
import subprocess

import numpy as np

from . import _masa


def _tool(name):
    """A masa tool: the build's own (beside this package in <build>/python), else on PATH."""
    here = os.path.dirname(os.path.abspath(__file__))
    built = os.path.join(here, "..", "..", "tools", name)
    if os.path.isfile(built) and os.access(built, os.X_OK):
        return os.path.normpath(built)
    found = shutil.which(name)
    if found is None:
        raise FileNotFoundError(f"{name}: not built beside this module and not on PATH "
                                f"(cmake --build build --target {name})")
    return found


def read_csv(path):
    """A CSV file with a header line as a dict of float64 columns."""
    with open(path) as f:
        names = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if data.size == 0:
        data = np.zeros((0, len(names)))
    return {n: data[:, k] for k, n in enumerate(names)}


class Run:
    """A run directory (masa_train's --run-dir): config, metrics, policy."""

    def __init__(self, path):
        self.path = os.fspath(path)
        if not os.path.isfile(os.path.join(self.path, "config.yaml")):
            raise FileNotFoundError(f"{self.path}: not a run directory (no config.yaml)")

    @property
    def config(self):
        """The run's resolved configuration (masa.RunConfig), read as the tools read it."""
        return _masa.load_config([], os.path.join(self.path, "config.yaml"))

    def config_dict(self):
        """The resolved configuration as nested dicts (PyYAML)."""
        import yaml
        with open(os.path.join(self.path, "config.yaml")) as f:
            return yaml.safe_load(f)

    @property
    def metrics(self):
        """metrics.csv as a dict of arrays, one entry per update (epoch, env_steps, return, ...)."""
        return read_csv(os.path.join(self.path, "metrics.csv"))

    def policy(self):
        from .policy import Policy
        return Policy.load(os.path.join(self.path, "policy.bin"))

    def evaluate(self, episodes=20, seed=0, **kwargs):
        return self.policy().evaluate(episodes=episodes, seed=seed, **kwargs)

    def __repr__(self):
        return f"masa.Run({self.path!r})"


def _build_dir():
    """The build tree this module belongs to (tools/, learner/, actors/ beside python/), or None
    for an installed module."""
    here = os.path.dirname(os.path.abspath(__file__))
    build = os.path.normpath(os.path.join(here, "..", ".."))
    return build if os.path.isfile(os.path.join(build, "CMakeCache.txt")) else None


def train(task, run_dir, updates=None, overrides=None, recipe=None, threads=None, quiet=True, check=True,
          launcher="masa_train", actors=2, envs=None):
    """Starts a training run and returns it when it ends (masa.Run). launcher: "masa_train" (a
    learner and an actor in one process) or "train.sh" (deploy/train.sh, the README's run: one
    masa_learner and `actors` masa_actor processes of `envs` environments each over loopback LCM,
    from this module's build tree). overrides: config keys as --set takes them. Errors: the
    launcher's message in a RuntimeError (check=False returns the Run whatever happened)."""
    from .env import _override_strings
    run_dir = os.path.abspath(os.fspath(run_dir))
    sets = []
    for s in _override_strings(overrides):
        sets += ["--set", s]
    if launcher == "masa_train":
        cmd = [_tool("masa_train"), "--run-dir", run_dir, "--set", f"task={task}"] + sets
        if threads is not None:
            cmd += ["--threads", str(int(threads))]
        if quiet:
            cmd.append("--quiet")
        cwd, env = None, None
    elif launcher == "train.sh":
        build = _build_dir()
        if build is None:
            raise FileNotFoundError("train.sh runs from a build tree; this module is installed (use launcher='masa_train')")
        cmd = ["bash", "deploy/train.sh", task, "--run-dir", run_dir, "--actors", str(int(actors))] + sets
        if envs is not None:
            cmd += ["--envs", str(int(envs))]
        cwd, env = _masa.source_dir(), dict(os.environ, MASA_BUILD_DIR=build)
    else:
        raise ValueError(f"launcher must be 'masa_train' or 'train.sh', got {launcher!r}")
    if recipe:
        cmd += ["--recipe", recipe]
    if updates is not None:
        cmd += ["--updates", str(int(updates))]
    done = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd, env=env)
    if check and done.returncode != 0:
        raise RuntimeError(done.stderr.strip() or f"{launcher} exited with {done.returncode}")
    return Run(run_dir)


def read_dataset(path):
    """An offline dataset (masa_dataset's recorded LCM logs, or its HDF5 export) as a dict of
    arrays: observations (N, obs_dim), actions, rewards, next_observations, terminals, timeouts,
    and the episodes' starts, lengths and returns."""
    paths = [os.fspath(p) for p in path] if isinstance(path, (list, tuple)) else [os.fspath(path)]
    return _masa.read_dataset(paths)
