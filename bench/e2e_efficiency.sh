#!/usr/bin/env bash
# How close a real training run (deploy/train.sh: learner + actors over loopback LCM) comes to what
# this machine could do: the bound cores / (t_env + t_learn) of bench_efficiency_bound against the
# run's steady-state fps (median over the updates after the warm-up, from its metrics.csv), in one
# run of this script, so the two see the same machine. Last line: "efficiency X" (fps / bound).
#   bench/e2e_efficiency.sh [--recipe a1_beam] [--scale S] [--actors K] [--updates N] [--warmup W] [--auth "MODE..."]
# --auth runs train.sh once per mode (signed, hmac, none; default: train.sh's own, signed), in the
# order given, against the same bound, and with two or more modes prints each one's fps over the
# first's ("fps ratio signed/hmac 0.99"): what signing costs end to end.
# --scale S multiplies the recipe's environments (and minibatch) by S (the issue's "4x its
# environments": --scale 4). MASA_BUILD_DIR (default build) chooses the binaries; the run uses its
# own LCM port (7695, or MASA_E2E_PORT) so it never mixes with a training run or a test.
set -euo pipefail
cd "$(dirname "$0")/.."
recipe=a1_beam scale=1 actors=2 updates=40 warmup=10 modes=""
while [ $# -gt 0 ]; do
  case "$1" in
    --recipe) recipe=$2; shift 2 ;;
    --scale) scale=$2; shift 2 ;;
    --actors) actors=$2; shift 2 ;;
    --updates) updates=$2; shift 2 ;;
    --warmup) warmup=$2; shift 2 ;;
    --auth) modes=$2; shift 2 ;;
    *) echo "e2e_efficiency.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
build=${MASA_BUILD_DIR:-build}
bash "$(dirname "$0")/build_benchmarks.sh" "$build"
resolved=$("$build/tools/masa_config" --set "@$recipe")
envs=$(sed -n 's/^  num_envs: //p' <<< "$resolved")
mb=$(sed -n 's/^  minibatch_size: //p' <<< "$resolved")
sets=(--set "ppo.num_envs=$((envs * scale))" --set "ppo.minibatch_size=$((mb * scale))")
echo "e2e_efficiency: recipe $recipe x$scale ($((envs * scale)) envs), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"

bound_out=$("$build/bench/bench_efficiency_bound" --recipe "$recipe" "${sets[@]}" --rounds 3)
echo "$bound_out"
bound=$(sed -n 's/^bound \([0-9.]*\) .*/\1/p' <<< "$bound_out")

run_dir=$(mktemp -d /tmp/masa_e2e_eff.XXXXXX)
first_fps="" first_mode="" n=0
for mode in ${modes:-default}; do
  n=$((n + 1))
  auth=()
  [ "$mode" = default ] || auth=(--auth "$mode")
  out=$run_dir/${n}_$mode  # a mode given twice (A B A B, against drift in the machine's load) runs twice
  MASA_LCM_URL="udpm://239.255.76.67:${MASA_E2E_PORT:-7695}?ttl=0&recv_buf_size=$(cat /proc/sys/net/core/rmem_max)" \
    bash deploy/train.sh --recipe "$recipe" --actors "$actors" --updates "$updates" --run-dir "$out" \
    "${auth[@]+"${auth[@]}"}" "${sets[@]}" --set runner.eval_every=0 > "$run_dir/train_${n}_$mode.log" 2>&1
  fps=$(awk -F, -v w="$warmup" 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "fps") c = i; next }
        $1 > w { print $c }' "$out/metrics.csv" | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }')
  [ -n "$fps" ] || { echo "e2e_efficiency.sh: no fps after the warm-up; see $run_dir/train_${n}_$mode.log" >&2; exit 1; }
  echo "train.sh${auth[*]:+ ${auth[*]}}: $actors actors, median fps $fps over updates $warmup..$((updates - 1)) (run dir $out)"
  [ "$mode" = default ] || awk -v f="$fps" -v b="$bound" -v m="$mode" 'BEGIN { printf "efficiency %s %.3f\n", m, f / b }'
  if [ -z "$first_fps" ]; then
    first_fps=$fps first_mode=$mode
  else
    awk -v f="$fps" -v g="$first_fps" -v m="$mode" -v n="$first_mode" 'BEGIN { printf "fps ratio %s/%s %.3f\n", m, n, f / g }'
  fi
done
awk -v f="$fps" -v b="$bound" 'BEGIN { printf "efficiency %.2f\n", f / b }'
