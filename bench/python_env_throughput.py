#!/usr/bin/env python3
"""Env steps per second through `import masa` against the same stepping in C++ (the actor's loop,
bench_python_env_baseline), same task, environments, threads and actions; the issue's target is a
ratio >= 0.9 for 64 environments. Alternates the two a few times and reports the medians.
    PYTHONPATH=build/python /usr/bin/python3 bench/python_env_throughput.py build [task] [num_envs] [threads]
(builds nothing: cmake --build build --target masa_python bench_python_env_baseline first)"""
import os
import statistics
import subprocess
import sys
import time

import numpy as np

import masa

ROUNDS, STEPS, BLOCKS = 5, 200, 16


def module_rate(task, n, threads):
    env = masa.make_env(task, num_envs=n, num_threads=threads)
    env.reset(seed=0)
    rng = np.random.default_rng(1)
    blocks = [rng.uniform(-1, 1, env.action_space.shape).astype(np.float32) for _ in range(BLOCKS)]
    for t in range(10):
        env.step(blocks[t % BLOCKS])
    began = time.perf_counter()
    for t in range(STEPS):
        env.step(blocks[t % BLOCKS])
    return STEPS * n / (time.perf_counter() - began)


def cpp_rate(build, task, n, threads):
    out = subprocess.run([os.path.join(build, "bench", "bench_python_env_baseline"), task, str(n), str(threads),
                          str(STEPS)], check=True, capture_output=True, text=True).stdout
    return float(out.split()[1])


def main():
    build = sys.argv[1]
    task = sys.argv[2] if len(sys.argv) > 2 else "a1_beam"
    n = int(sys.argv[3]) if len(sys.argv) > 3 else 64
    threads = int(sys.argv[4]) if len(sys.argv) > 4 else 2
    py, cpp = [], []
    for _ in range(ROUNDS):
        cpp.append(cpp_rate(build, task, n, threads))
        py.append(module_rate(task, n, threads))
    p, c = statistics.median(py), statistics.median(cpp)
    print(f"{task}, {n} environments, {threads} threads, {STEPS} steps x {ROUNDS} rounds (medians)")
    print(f"  C++ (actor's loop): {c:10.0f} env steps/s   {sorted(round(x) for x in cpp)}")
    print(f"  masa module:        {p:10.0f} env steps/s   {sorted(round(x) for x in py)}")
    print(f"  ratio module / C++: {p / c:.3f}")


main()
