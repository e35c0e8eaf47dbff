"""A shipped policy's actions through the module equal masa_eval's: episodes stepped in Python
(masa.make_env of the policy's task, Policy.act on the batch) give masa_eval's per-episode
returns and lengths for the same seeds, to the CSV's 9 digits, and Policy.evaluate gives them
exactly. Actions off by 1e-3 must give other returns (the comparison can fail).
    test_policy_equals_eval.py <masa_eval> <work dir>"""
import os
import subprocess
import sys

import numpy as np

import masa
from masa.runs import read_csv
from masa_test_util import run

SOURCE = os.path.dirname(masa._masa.configs_dir())
EPISODES, SEED, STEPS = 4, 5, 60


def python_returns(policy, offset=0.0):
    env = policy.make_env(num_envs=EPISODES, seed=SEED, num_threads=2)
    obs, _ = env.reset(seed=SEED)
    returns, lengths = np.zeros(EPISODES), np.zeros(EPISODES, int)
    alive = np.ones(EPISODES, bool)
    for _ in range(STEPS):
        obs, reward, terminated, truncated, _ = env.step(policy.act(obs) + np.float32(offset))
        returns[alive] += reward[alive]
        lengths[alive] += 1
        alive &= ~(terminated | truncated)
    return returns, lengths


def main():
    tool, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    failures = []
    for task in ("a1_beam", "trifinger_lift"):
        path = os.path.join(SOURCE, "tasks", task, "policy", "policy.bin")
        csv = os.path.join(work, f"{task}.csv")
        subprocess.run([tool, path, "--episodes", str(EPISODES), "--seed", str(SEED), "--max-steps", str(STEPS),
                        "--csv", csv], check=True, capture_output=True)
        expected = read_csv(csv)
        policy = masa.Policy.load(path)
        returns, lengths = python_returns(policy)
        if not np.allclose(returns, expected["return"], rtol=2e-8, atol=1e-6):
            failures.append(f"{task}: returns {returns} differ from masa_eval's {expected['return']}")
        if not np.array_equal(lengths, expected["length"].astype(int)):
            failures.append(f"{task}: lengths {lengths} differ from masa_eval's {expected['length']}")
        evaluated = policy.evaluate(episodes=EPISODES, seed=SEED, max_steps=STEPS)
        if not np.array_equal(evaluated["return"], returns):
            failures.append(f"{task}: Policy.evaluate's returns {evaluated['return']} differ from the loop's {returns}")
        off, _ = python_returns(policy, 1e-3)
        if np.allclose(off, expected["return"], rtol=2e-8, atol=1e-6):
            failures.append(f"{task}: actions off by 1e-3 gave masa_eval's returns: the comparison is vacuous")
        print(f"{task}: returns {np.round(returns, 6)} equal masa_eval's")
    if not failures:
        print("PASS: shipped policies act through the module as in masa_eval")
    return failures


run(main)
