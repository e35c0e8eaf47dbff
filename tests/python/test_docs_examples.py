"""The Python examples of docs/python.md and README.md run as written: every ```python block, in
a fresh interpreter, from the repository root (the examples' paths are the root's), with the
module on PYTHONPATH. A block that renders runs under xvfb-run when there is no display (and is
skipped, said so, where neither is). A failing block prints its output and FAIL:.
    test_docs_examples.py <source root> <doc.md>[#Section]...
(#Section: only the blocks under that "## Section" heading, e.g. README.md#Python, whose other
examples need files made by earlier commands.)"""
import os
import re
import shutil
import subprocess
import sys

from masa_test_util import run

BLOCK = re.compile(r"^```python\n(.*?)^```", re.S | re.M)


def main():
    root, docs = sys.argv[1], sys.argv[2:]
    failures, ran = [], 0
    for doc in docs:
        path, _, section = doc.partition("#")
        text = open(os.path.join(root, path)).read()
        if section:
            start = text.find(f"\n## {section}\n")
            end = text.find("\n## ", start + 1)
            text = text[start:end if end >= 0 else len(text)] if start >= 0 else ""
        blocks = BLOCK.findall(text)
        if not blocks:
            failures.append(f"{doc}: no Python examples found")
        for k, code in enumerate(blocks):
            cmd = [sys.executable, "-c", code]
            if ".render(" in code and not os.environ.get("DISPLAY"):
                if shutil.which("xvfb-run") is None:
                    print(f"{doc} example {k + 1}: skipped (renders; no display and no xvfb-run)")
                    continue
                cmd = ["xvfb-run", "-a"] + cmd
            done = subprocess.run(cmd, cwd=root, capture_output=True, text=True, timeout=240)
            ran += 1
            if done.returncode != 0:
                print(done.stdout[-3000:], done.stderr[-3000:])
                failures.append(f"{doc} example {k + 1} (line '{code.splitlines()[0]}' ...) exited with {done.returncode}")
            else:
                print(f"{doc} example {k + 1}: ran ({len(code.splitlines())} lines)")
    if not failures:
        print(f"PASS: the {ran} Python examples of {', '.join(docs)} run as written")
    return failures


run(main)
