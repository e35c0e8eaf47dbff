#!/usr/bin/env python3
"""Run a tool test's command and judge it by its exit status and its output, both.

    expect.py EXIT REGEX -- COMMAND [ARG...]

ctest's PASS_REGULAR_EXPRESSION ignores the exit status: a tool that printed its success line and
then failed (a crash at exit, a non-zero status) passed. masa_tool_test (tests/CMakeLists.txt) runs
every tool test through this script instead. It passes the command's output through as it comes
(stdout and stderr together, as ctest shows them) and exits 0 only when the command exited with
EXIT and its output matches REGEX, searched as ctest searched it: anywhere in the whole output,
'.' matching a newline too, '^' and '$' at the output's start and end.

A command that exits 77 (a test's "skip": root, a package or a device missing) exits 77 here as
well, so that a test's SKIP_RETURN_CODE 77 still skips it, unless 77 is the status expected.
"""
import re
import subprocess
import sys


def main() -> int:
    if len(sys.argv) < 5 or sys.argv[3] != "--":
        print("usage: expect.py EXIT REGEX -- COMMAND [ARG...]", file=sys.stderr)
        return 2
    try:
        want = int(sys.argv[1])
    except ValueError:
        print(f"expect.py: the expected exit status '{sys.argv[1]}' is not a number", file=sys.stderr)
        return 2
    try:
        pattern = re.compile(sys.argv[2], re.DOTALL)
    except re.error as e:
        print(f"expect.py: the expected output '{sys.argv[2]}' is not a regular expression: {e}", file=sys.stderr)
        return 2
    command = sys.argv[4:]
    out = sys.stdout.buffer
    chunks = []
    try:
        proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    except OSError as e:
        print(f"expect.py: FAIL: cannot run {command[0]}: {e}")
        return 1
    while True:
        chunk = proc.stdout.read1(65536)
        if not chunk:
            break
        chunks.append(chunk)
        out.write(chunk)
        out.flush()
    status = proc.wait()
    text = b"".join(chunks).decode("utf-8", "replace")
    if status == 77 and want != 77:
        print("expect.py: the command exited 77 (skip)")
        return 77
    problems = []
    if status != want:
        got = f"killed by signal {-status}" if status < 0 else f"exit status {status}"
        problems.append(f"{got}, expected {want}")
    if not pattern.search(text):
        problems.append(f"the output does not match {sys.argv[2]!r}")
    if problems:
        print("\nexpect.py: FAIL: " + "; ".join(problems))
        return 1
    print(f"\nexpect.py: exit status {status} and the output as expected")
    return 0


if __name__ == "__main__":
    sys.exit(main())
