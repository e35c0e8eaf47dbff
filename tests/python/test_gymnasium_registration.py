"""With Gymnasium importable, `import masa` registers every catalog task as masa/<task>-v0 with a
vector entry point that makes the batched environment, and the spaces are Gymnasium's Box. The
Gymnasium here is a stand-in (Debian has none): a package with register(), a registry and
spaces.Box, put first on sys.path, as a user's Gymnasium would be found."""
import os
import sys
import tempfile

from masa_test_util import run

STAND_IN = {
    "__init__.py": (
        "registry = {}\n"
        "def register(id, entry_point=None, vector_entry_point=None, **kwargs):\n"
        "    registry[id] = vector_entry_point\n"),
    "spaces.py": (
        "import numpy as np\n"
        "class Box:\n"
        "    def __init__(self, low, high, shape=None, dtype=np.float32, seed=None):\n"
        "        self.low, self.high, self.shape, self.dtype = low, high, tuple(shape), np.dtype(dtype)\n"),
}


def main():
    folder = tempfile.mkdtemp()
    os.makedirs(os.path.join(folder, "gymnasium"))
    for name, text in STAND_IN.items():
        open(os.path.join(folder, "gymnasium", name), "w").write(text)
    sys.path.insert(0, folder)
    import gymnasium
    import masa
    failures = []
    wanted = {f"masa/{t}-v0" for t in masa.task_names()}
    if set(gymnasium.registry) != wanted:
        failures.append(f"registered {sorted(gymnasium.registry)}, expected {sorted(wanted)}")
    env = gymnasium.registry["masa/c4_walker-v0"](num_envs=3, seed=2)
    if not isinstance(env, masa.VectorEnv) or env.num_envs != 3 or env.task != "c4_walker":
        failures.append(f"masa/c4_walker-v0 made {env!r}")
    if type(env.single_action_space) is not gymnasium.spaces.Box:
        failures.append(f"the action space is a {type(env.single_action_space)}, not Gymnasium's Box")
    obs, _ = env.reset()
    if obs.shape != (3,) + env.single_observation_space.shape:
        failures.append(f"reset gave shape {obs.shape}")
    if not failures:
        print(f"PASS: {len(wanted)} tasks registered with Gymnasium, made by gymnasium's entry point")
    return failures


run(main)
