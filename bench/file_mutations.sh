#!/usr/bin/env bash
# The file mutation experiment of issue #33: N randomly damaged copies of a policy file
# (bench/mutate_file.py, seeded), each given to masa_eval as a user would; every run is classed as
#   crash    killed by a signal (exit status >= 128)
#   hang     still running after the time limit (timeout's 124)
#   refused  exit status 1 or 2 with a message (the last line of stderr is kept)
#   accepted exit status 0: the damaged file was loaded and evaluated
# and the mutations that left the bytes as they were are counted apart.
#   bench/file_mutations.sh MASA_EVAL POLICY [N=300] [SEED=33] [TIME_LIMIT_S=120]
# e.g. bench/file_mutations.sh build/tools/masa_eval tasks/a1_beam/policy/policy.bin
set -uo pipefail
eval_bin=${1:?masa_eval binary}
policy=${2:?policy file}
n=${3:-300}
seed=${4:-33}
limit=${5:-120}
work=$(mktemp -d /tmp/masa_file_mutations.XXXXXX)
trap 'rm -rf "$work"' EXIT
here=$(cd "$(dirname "$0")" && pwd)
python3 "$here/mutate_file.py" "$policy" "$work" "$n" "$seed"

echo "file_mutations: $(date -u +%FT%TZ), $eval_bin ($("$eval_bin" --version 2>/dev/null | head -1)), $policy ($(stat -c %s "$policy") bytes, sha256 $(sha256sum "$policy" | cut -c1-16)), $n mutations, seed $seed, limit ${limit}s, $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
crash=0 hang=0 refused=0 accepted=0 unchanged=0
for ((i = 0; i < n; i++)); do
  f=$(printf '%s/%03d.bin' "$work" "$i")
  what=$(sed -n "$((i + 1))p" "$work/mutations.txt" | cut -d' ' -f2-)
  timeout "$limit" "$eval_bin" "$f" --episodes 1 --threads 1 >"$work/out" 2>"$work/err"
  rc=$?
  if [[ $what == *"(bytes unchanged)"* ]]; then unchanged=$((unchanged + 1)); class=unchanged
  elif [ $rc -eq 124 ]; then hang=$((hang + 1)); class=hang
  elif [ $rc -ge 128 ]; then crash=$((crash + 1)); class=crash
  elif [ $rc -eq 0 ]; then accepted=$((accepted + 1)); class=accepted
  else refused=$((refused + 1)); class=refused
  fi
  printf '%03d %-8s rc=%-3d %-40s %s\n' "$i" "$class" "$rc" "$what" "$(tail -1 "$work/err" | sed "s|$work/||g" | cut -c1-140)"
done
echo "total $n: crash $crash, hang $hang, refused $refused, accepted $accepted, unchanged bytes $unchanged"
