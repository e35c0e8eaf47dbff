#!/usr/bin/env python3
"""Reproduces a shipped policy's evaluation from Python: the policy file loaded and checked as
masa_eval loads it, its task as it was trained, episode i reset from seed i, the policy's mean
actions, and the per-episode returns compared with the shipped eval.csv (masa_eval --csv).
    PYTHONPATH=build/python /usr/bin/python3 python/examples/reproduce_eval.py [task] [episodes]
Run from the repository root."""
import sys

import numpy as np

import masa
from masa.runs import read_csv

task = sys.argv[1] if len(sys.argv) > 1 else "a1_beam"
episodes = int(sys.argv[2]) if len(sys.argv) > 2 else 20
folder = f"tasks/{task}/policy"

policy = masa.Policy.load(f"{folder}/policy.bin")
print(f"{policy}: {policy.integrity}; equivariance error {policy.symmetry_error:.1e}")
env = policy.make_env(num_envs=episodes)
obs, _ = env.reset(seed=0)  # environment i starts from seed i, as masa_eval's episode i
returns = np.zeros(episodes)
lengths = np.zeros(episodes, dtype=int)
running = np.ones(episodes, dtype=bool)
while running.any():
    obs, reward, terminated, truncated, infos = env.step(policy.act(obs))
    returns[running] += reward[running]
    lengths[running] += 1
    running &= ~(terminated | truncated)  # the first episode of each environment is the one measured

shipped = read_csv(f"{folder}/eval.csv")
n = min(episodes, len(shipped["return"]))
print(f"{'episode':>7} {'return (Python)':>16} {'return (eval.csv)':>18} {'length':>7}")
for i in range(n):
    print(f"{i:7d} {returns[i]:16.5f} {shipped['return'][i]:18.5f} {lengths[i]:7d}")
same = np.allclose(returns[:n], shipped["return"][:n], rtol=1e-8) and np.array_equal(lengths[:n], shipped["length"][:n])
print(f"mean return {returns.mean():.3f} over {episodes} episodes; "
      + ("the same as the shipped evaluation" if same else "DIFFERENT from the shipped evaluation"))
sys.exit(0 if same else 1)
