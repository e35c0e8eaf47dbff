"""The examples of python/examples/ run from the repository root and succeed (each exits non-zero
when its result is wrong): reproduce_eval.py gives the shipped eval.csv's returns for a1_beam's
first episodes; train_torch.py (--quick) trains a student that walks. Without PyTorch the torch
example is skipped, saying so.
    test_examples.py <source root> reproduce_eval|train_torch"""
import importlib.util
import subprocess
import sys

from masa_test_util import run

COMMANDS = {
    "reproduce_eval": ["python/examples/reproduce_eval.py", "a1_beam", "4"],
    "train_torch": ["python/examples/train_torch.py", "--quick"],
}


def main():
    root, which = sys.argv[1], sys.argv[2]
    if which == "train_torch" and importlib.util.find_spec("torch") is None:
        print("SKIP: PyTorch is not installed (Debian: apt-get install python3-torch)")
        return []
    done = subprocess.run([sys.executable] + COMMANDS[which], cwd=root, capture_output=True, text=True, timeout=280)
    print(done.stdout[-2000:], done.stderr[-2000:])
    if done.returncode != 0:
        return [f"python/examples/{which}.py exited with {done.returncode}"]
    print(f"PASS: python/examples/{which}.py ran and its result holds")
    return []


run(main)
