"""Bad input raises Python exceptions carrying the tools' own messages, and never crashes: a
wrong task name and a wrong config key (masa_config's words), a damaged or cut policy file
(masa_eval's), wrong array shapes and dtypes (the task's words: what was given, what was
expected), a group element out of range.
    test_errors.py <masa_config> <masa_eval> <work dir>"""
import os
import shutil
import subprocess
import sys

import numpy as np

import masa
from masa_test_util import run

SOURCE = os.path.dirname(masa._masa.configs_dir())


def tool_message(cmd, prefix):
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode == 0:
        return None
    line = done.stderr.strip().splitlines()[-1]
    return line[len(prefix):] if line.startswith(prefix) else line


def raised(f, kind):
    try:
        f()
    except kind as e:
        return str(e)
    except Exception as e:  # the wrong kind: reported with its type
        return f"<{type(e).__name__}: {e}>"
    return None


def main():
    masa_config, masa_eval, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    failures = []

    def expect_same(what, got, expected):
        if got is None:
            failures.append(f"{what}: nothing was raised")
        elif expected is None:
            failures.append(f"{what}: the tool accepted it")
        elif got != expected:
            failures.append(f"{what}: raised {got!r}, the tool says {expected!r}")
        else:
            print(f"{what}: {got}")

    expect_same("a wrong task name", raised(lambda: masa.make_env("a1_bem", num_envs=2), masa.ConfigError),
                tool_message([masa_config, "--set", "task=a1_bem"], "masa_config: "))
    expect_same("a wrong config key",
                raised(lambda: masa.make_env("a1_beam", overrides={"ppo.learning_rat": 1e-3}), masa.ConfigError),
                tool_message([masa_config, "--set", "task=a1_beam", "--set", "ppo.learning_rat=1e-3"], "masa_config: "))

    shipped = os.path.join(SOURCE, "tasks", "a1_beam", "policy", "policy.bin")
    damaged, cut = os.path.join(work, "damaged.bin"), os.path.join(work, "cut.bin")
    data = bytearray(open(shipped, "rb").read())
    data[len(data) // 2] ^= 0x40
    open(damaged, "wb").write(data)
    open(cut, "wb").write(data[: len(data) // 3])
    for what, path in (("a damaged policy file", damaged), ("a cut policy file", cut)):
        expect_same(what, raised(lambda: masa.Policy.load(path), RuntimeError),
                    tool_message([masa_eval, path, "--episodes", "1", "--max-steps", "1"], "masa_eval: "))

    env = masa.make_env("a1_beam", num_envs=4)
    env.reset(seed=0)
    policy = masa.Policy.load(shipped)
    checks = [
        ("actions of a wrong shape", lambda: env.step(np.zeros((3, 12), np.float32)), ValueError,
         "task a1_beam: actions have shape (3, 12), expected (4, 12)"),
        ("actions of one environment", lambda: env.step(np.zeros(12, np.float32)), ValueError,
         "task a1_beam: actions have shape (12,), expected (4, 12)"),
        ("integer actions", lambda: env.step(np.zeros((4, 12), np.int64)), TypeError,
         "task a1_beam: actions have dtype int64, expected float32 (or float64)"),
        ("actions as a list", lambda: env.step([[0.0] * 12] * 4), TypeError,
         "task a1_beam: actions must be a NumPy array, got list"),
        ("observations of a wrong width", lambda: policy.act(np.zeros((2, 46), np.float32)), ValueError,
         f"policy {shipped}: observations have shape (2, 46), expected (N, 47)"),
        ("a group element out of range", lambda: env.symmetry.transform_obs(np.zeros((1, 47), np.float32), 2),
         IndexError, "symmetry a1_beam: element 2 of a group of 2"),
        ("no environments", lambda: masa.make_env("a1_beam", num_envs=0), ValueError,
         "num_envs must be a positive integer, got 0"),
    ]
    for what, f, kind, message in checks:
        got = raised(f, kind)
        if got != message:
            failures.append(f"{what}: raised {got!r}, expected {kind.__name__} {message!r}")
        else:
            print(f"{what}: {kind.__name__}: {got}")
    # Still usable after every error.
    obs, reward, *_ = env.step(np.zeros((4, 12), np.float64))
    if obs.shape != (4, 47) or not np.all(np.isfinite(reward)):
        failures.append("the environment does not step after the errors")
    if not failures:
        print("PASS: bad input raises the tools' messages and nothing crashed")
    return failures


run(main)
