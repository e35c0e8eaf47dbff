#!/usr/bin/env bash
# deploy/train.sh --hosts FILE under random damage (docs/inputs.md gap 7): 80 seeded mutations of
# a hosts file (bit flips, cut lines, shell syntax, options, quotes, huge or negative counts, binary
# bytes) each given to train.sh with a stand-in ssh that records what it is asked and fails. For
# every one: no hang; no command hidden in the file runs; every host name that reaches ssh is a
# plain [user@]host; and a refusal is train.sh's own message, never a bash error. Stand-in programs
# for the learner and actors, so that a file that names only localhost ends at once.
#   tests/integration/hosts_file_fuzz.sh [BUILD_DIR]
set -uo pipefail
source "$(dirname "$0")/lib.sh"
[ $# -ge 1 ] && build=$(cd "$1" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/masa_hosts_fuzz.XXXXXX")
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

stub=$work/build
mkdir -p "$stub/learner" "$stub/actors" "$stub/tools"
printf '#!/bin/sh\nexit 3\n' > "$stub/learner/masa_learner"
cp "$stub/learner/masa_learner" "$stub/actors/masa_actor"
chmod +x "$stub/learner/masa_learner" "$stub/actors/masa_actor"
ln -s "$build/tools/masa_config" "$stub/tools/masa_config"
ln -s "$build/tools/masa_roster" "$stub/tools/masa_roster"
cat > "$work/ssh" << 'SSH'
#!/usr/bin/env bash
printf '%s\0' "$1" >> "$FAKE_SSH_HOSTS"
exit 1
SSH
chmod +x "$work/ssh"

python3 - "$work/cases" << 'PY'
import os, random, sys
out = sys.argv[1]; os.makedirs(out)
rng = random.Random(20261204)
base = b"# actors of the run\nnode1 2 16\nuser@node-2.lan 1   # one actor\n[fe80::1%eth0] 1 8\nlocalhost 1\n"
hostile = [b"-oProxyCommand=touch${IFS}PWNED", b"$(touch${IFS}PWNED)", b"`touch${IFS}PWNED`", b"a;touch${IFS}PWNED",
           b"a|touch${IFS}PWNED", b"a&&touch${IFS}PWNED", b"a>PWNED", b"-F/etc/passwd", b"--", b"-", b"@", b"a\nb", b"'a'", b'"a"', b"a b c d", b"0", b"-1", b"99999999999999999999999", b"1e3", b"0x10",
           b"\\", b"\t", b"\r", b"\x00", b"\xff\xfe", "n\u00f6de".encode(), b"*", b"~", b"..", b"a" * 5000, b"#", b"="]
for i in range(80):
    d = bytearray(base)
    for _ in range(rng.randint(1, 4)):
        op = rng.randrange(5)
        if op == 0 and d:  # flip a bit
            k = rng.randrange(len(d)); d[k] ^= 1 << rng.randrange(8)
        elif op == 1:  # splice hostile text in
            k = rng.randrange(len(d) + 1); d[k:k] = rng.choice(hostile)
        elif op == 2 and d:  # replace a field
            words = bytes(d).split(b" "); words[rng.randrange(len(words))] = rng.choice(hostile); d = bytearray(b" ".join(words))
        elif op == 3 and d:  # cut
            d = d[:rng.randrange(len(d))]
        else:  # a random byte
            k = rng.randrange(len(d) + 1); d[k:k] = bytes([rng.randrange(256)])
    open(os.path.join(out, "%03d" % i), "wb").write(bytes(d))
PY

refused=0 accepted=0
for f in "$work"/cases/*; do
  i=$(basename "$f")
  : > "$work/hosts_$i"
  (cd "$work" && FAKE_SSH_HOSTS="$work/hosts_$i" MASA_REMOTE_SHELL="$work/ssh" MASA_BUILD_DIR="$stub" \
     timeout 20 bash "$masa_repo/deploy/train.sh" a1_beam masa --hosts "$f" --updates 1 --run-dir "$work/run_$i" \
     > "$work/out_$i" 2>&1 < /dev/null)
  rc=$?
  [ "$rc" = 124 ] && fail "case $i: train.sh hung"
  if grep -aEq '(train\.sh|bash): line [0-9]+:|unbound variable|syntax error|command not found' "$work/out_$i"; then
    fail "case $i: a bash error, not a refusal: $(grep -aE 'line [0-9]+:|unbound|syntax|not found' "$work/out_$i" | head -n 2)"
  fi
  grep -aq 'is not a host name\|expected .host \[actors\] \[envs\]\|lists no host' "$work/out_$i" && refused=$((refused + 1)) || accepted=$((accepted + 1))
  while IFS= read -r -d '' h; do
    [[ $h =~ ^[][A-Za-z0-9_.@:%][][A-Za-z0-9_.@:%-]*$ ]] || fail "case $i: ssh was given the host '$h'"
  done < "$work/hosts_$i"
done
found=$(find "$work" "$masa_repo" -maxdepth 3 -name 'PWNED*' 2> /dev/null | head -n 1)
[ -z "$found" ] || fail "a command in a hosts file ran: $found"
echo "hosts files: 80 mutations, $refused refused by line, $accepted parsed (then stopped by the stand-in ssh or learner)"
[ "$refused" -gt 20 ] || fail "only $refused of 80 damaged files refused: the damage is too mild to test anything"
[ "$failures" = 0 ] && echo "PASS: no hang, no command run, only plain host names reach ssh, every refusal train.sh's own"
exit $((failures > 0))
