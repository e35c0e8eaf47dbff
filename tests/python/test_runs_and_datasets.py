"""Runs and datasets from Python: masa.train starts a run with masa_train (and with deploy/train.sh:
a learner and two actor processes over loopback LCM), masa.Run reads its
config (as the tools resolve it) and its metrics as arrays equal to metrics.csv read by Python's
csv module, and evaluates its policy; masa.read_dataset reads masa_dataset's LCM log and its HDF5
export, both equal to the export read by h5py, the episodes' returns those of masa_eval's episodes
(Policy.evaluate, same seeds, limit and mean actions). A wrong key in train() raises masa_train's message.
    test_runs_and_datasets.py <masa_dataset> <work dir>"""
import csv
import os
import shutil
import subprocess
import sys

import numpy as np

import masa
from masa_test_util import run

SOURCE = os.path.dirname(masa._masa.configs_dir())
TINY = {"model.policy_hidden": [16], "model.critic_hidden": [16], "ppo.num_envs": 8, "ppo.horizon": 8,
        "ppo.minibatch_size": 64, "env.max_episode_steps": 40}


def check_run(work, failures):
    run_dir = os.path.join(work, "run")
    r = masa.train("a1_beam", run_dir, updates=2, overrides=TINY, threads=1)
    if r.config.task != "a1_beam" or r.config_dict()["ppo"]["horizon"] != 8:
        failures.append(f"the run's config reads task {r.config.task}, horizon {r.config_dict()['ppo']['horizon']}")
    with open(os.path.join(run_dir, "metrics.csv")) as f:
        rows = list(csv.DictReader(f))
    metrics = r.metrics
    if len(rows) != 2 or set(metrics) != set(rows[0]):
        failures.append(f"metrics: {len(rows)} rows, columns {sorted(metrics)} against {sorted(rows[0]) if rows else []}")
    else:
        for name in ("env_steps", "return", "actor_loss"):
            if not np.allclose(metrics[name], [float(row[name]) for row in rows], equal_nan=True):
                failures.append(f"metrics[{name!r}] = {metrics[name]} differs from metrics.csv")
    evaluated = r.evaluate(episodes=2, max_steps=20)
    if evaluated["return"].shape != (2,) or not np.all(evaluated["length"] == 20):
        failures.append(f"evaluating the run gave {evaluated['return']}, lengths {evaluated['length']}")
    launched = masa.train("a1_beam", os.path.join(work, "launched"), updates=2, overrides=TINY, launcher="train.sh",
                          actors=2, envs=4)
    actor_logs = sorted(f for f in os.listdir(launched.path) if f.startswith("actor"))
    if list(launched.metrics["env_steps"]) != [64, 128] or actor_logs != ["actor0.log", "actor1.log"]:
        failures.append(f"train.sh's run: env_steps {launched.metrics['env_steps']}, actor logs {actor_logs}")
    try:
        masa.train("a1_beam", os.path.join(work, "bad"), updates=1, overrides={"ppo.horizn": 8})
        failures.append("train() with a wrong key did not raise")
    except RuntimeError as e:
        if "ppo.horizn" not in str(e) or "did you mean 'horizon'" not in str(e):
            failures.append(f"train() with a wrong key raised {e}")
    print(f"run: {len(rows)} updates, returns {metrics['return']}, evaluation {evaluated['return']}")


def check_dataset(tool, work, failures):
    import h5py
    policy_path = os.path.join(SOURCE, "tasks", "a1_beam", "policy", "policy.bin")
    log, h5 = os.path.join(work, "a1.lcmlog"), os.path.join(work, "a1.h5")
    for path in (log, h5):
        if os.path.exists(path):
            os.remove(path)
    subprocess.run([tool, "record", policy_path, "--episodes", "3", "--max-steps", "30", "--mean", "--out", log], check=True,
                   capture_output=True)
    subprocess.run([tool, "export", log, "--hdf5", h5], check=True, capture_output=True)
    f = h5py.File(h5, "r")
    for source in (log, h5):
        d = masa.read_dataset(source)
        for name in ("observations", "actions", "rewards", "next_observations", "terminals", "timeouts"):
            if not np.array_equal(d[name], f[name][()].astype(d[name].dtype)):
                failures.append(f"read_dataset({os.path.basename(source)})[{name!r}] differs from h5py's")
        for name in ("start", "length", "return"):
            if not np.array_equal(d["episodes"][name], f["episodes"][name][()].astype(d["episodes"][name].dtype)):
                failures.append(f"read_dataset({os.path.basename(source)}) episodes[{name!r}] differ from h5py's")
    d = masa.read_dataset(log)
    expected = masa.Policy.load(policy_path).evaluate(episodes=3, seed=0, max_steps=30)["return"]
    if not np.allclose(d["episodes"]["return"], expected, rtol=1e-5):  # the log sums float32 rewards
        failures.append(f"the recorded returns {d['episodes']['return']} are not masa_eval's {expected}")
    print(f"dataset: {d['observations'].shape[0]} transitions of {d['task']}, returns {d['episodes']['return']}")


def main():
    tool, work = sys.argv[1], sys.argv[2]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    failures = []
    check_run(work, failures)
    check_dataset(tool, work, failures)
    if not failures:
        print("PASS: a run started, read and evaluated from Python; datasets read as h5py reads their export")
    return failures


run(main)
