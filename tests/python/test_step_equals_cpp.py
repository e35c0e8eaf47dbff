"""A step of every catalog task through masa.make_env equals the C++ task's step for the same
seed and actions, bit for bit: observations, rewards, terminated, truncated, through episode
ends (a 10-step time limit) and their resets. Actions beyond [-1, 1] check the clamping too.
A perturbed action must show up as a difference (the comparison is not vacuous).
    test_step_equals_cpp.py <masa_python_step_reference> <work dir>"""
import os
import subprocess
import sys

import numpy as np

import masa
from masa_test_util import run

N, SEED, STEPS = 3, 7, 24
OVERRIDES = ["env.max_episode_steps=10"]


def reference(tool, work, task, actions):
    a_path, o_path = os.path.join(work, f"{task}_actions.bin"), os.path.join(work, f"{task}_out.bin")
    actions.astype(np.float32).tofile(a_path)
    subprocess.run([tool, task, str(N), str(SEED), str(STEPS), a_path, o_path] + OVERRIDES, check=True)
    return open(o_path, "rb").read()


def module_bytes(task, actions):
    env = masa.make_env(task, num_envs=N, overrides=OVERRIDES, num_threads=2)
    obs, _ = env.reset(seed=SEED)
    out = [obs.tobytes()]
    ends = 0
    for t in range(STEPS):
        obs, reward, terminated, truncated, infos = env.step(actions[t])
        assert obs.dtype == np.float32 and reward.dtype == np.float64 and terminated.dtype == bool
        out += [obs.tobytes(), reward.tobytes(), terminated.astype(np.uint8).tobytes(),
                truncated.astype(np.uint8).tobytes()]
        ends += int(np.sum(terminated | truncated))
    return b"".join(out), ends


def main():
    tool, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    failures = []
    tasks = masa.task_names()
    if len(tasks) < 5:
        failures.append(f"the catalog has only {tasks}")
    for task in tasks:
        env = masa.make_env(task, num_envs=N, overrides=OVERRIDES, num_threads=1)
        rng = np.random.default_rng(11)
        actions = rng.uniform(-1.3, 1.3, size=(STEPS, N, env.single_action_space.shape[0])).astype(np.float32)
        expected = reference(tool, work, task, actions)
        got, ends = module_bytes(task, actions)
        if got != expected:
            failures.append(f"{task}: the module's steps differ from the C++ task's ({len(got)} vs {len(expected)} bytes)")
            continue
        if ends == 0:
            failures.append(f"{task}: no episode ended in {STEPS} steps: the resets were not compared")
        perturbed = actions.copy()
        perturbed[3, 1, 0] = -perturbed[3, 1, 0]
        if module_bytes(task, perturbed)[0] == expected:
            failures.append(f"{task}: a perturbed action changed nothing: the comparison is vacuous")
        print(f"{task}: {STEPS} steps of {N} environments equal the C++ task's ({ends} episode ends)")
    if not failures:
        print(f"PASS: every catalog task ({len(tasks)}) steps through the module exactly as in C++")
    return failures


run(main)
