#!/usr/bin/env bash
# The tool tests' wrapper (tests/tools/expect.py) can fail: a command that prints its success line
# and then exits non-zero, or is killed, fails; one that exits 0 without the line fails; a refusal
# passes with its own status only; 77 (skip) comes back as 77.
#   bash tests/tools/expect_check.sh
set -uo pipefail
expect="$(dirname "$0")/expect.py"
failures=0
case_() {  # case_ WANT_STATUS WANT_LINE -- expect.py's arguments
  local want=$1 line=$2
  shift 3
  local out
  out=$(python3 "$expect" "$@" 2>&1)
  local got=$?
  if [ "$got" -ne "$want" ] || ! grep -qF -- "$line" <<<"$out"; then
    echo "FAIL: expect.py $* exited $got (want $want) with: $out"
    failures=$((failures + 1))
  else
    echo "ok: exit $got, '$line'"
  fi
}
case_ 1 "expect.py: FAIL: exit status 3, expected 0" -- 0 '(^|\n)PASS: ' -- bash -c 'echo "PASS: all done"; exit 3'
case_ 1 "expect.py: FAIL: killed by signal 11, expected 0" -- 0 '(^|\n)PASS: ' -- bash -c 'echo "PASS: all done"; kill -SEGV $$'
case_ 1 "expect.py: FAIL: the output does not match 'PASS: '" -- 0 'PASS: ' -- bash -c 'echo nothing'
case_ 1 "expect.py: FAIL: exit status 1, expected 2" -- 2 'refused' -- bash -c 'echo refused; exit 1'
case_ 0 "expect.py: exit status 2 and the output as expected" -- 2 'refused' -- bash -c 'echo refused; exit 2'
case_ 0 "expect.py: exit status 0 and the output as expected" -- 0 '^first.*\nlast$' -- bash -c 'echo first; echo middle >&2; echo last'
case_ 77 "expect.py: the command exited 77 (skip)" -- 0 'x' -- bash -c 'exit 77'
case_ 1 "expect.py: FAIL: cannot run" -- 0 'x' -- /no/such/program
case_ 2 "usage: expect.py" -- 0 'x' bash
[ "$failures" -eq 0 ] || { echo "FAIL: $failures case(s)"; exit 1; }
echo "PASS: expect.py failed each command whose exit status or output was not the expected one"
