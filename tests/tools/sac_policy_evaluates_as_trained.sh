#!/usr/bin/env bash
# masa_sac's policy.bin read by masa_eval (issue #34): a short SAC run, then masa_eval on its run
# directory with the learner's evaluation seeds (1000000 + k) must measure the same mean return and
# length as the run's last metrics row (its evaluation of tanh(mean)), to the row's 7 digits.
# usage: sac_policy_evaluates_as_trained.sh MASA_SAC MASA_EVAL WORK_DIR EPISODES [masa_sac settings...]
# Prints "SAME: ..." or "DIFFERENT: ..." (and exits 1).
set -euo pipefail
sac=$1
eval=$2
work=$3
episodes=$4
shift 4
rm -rf "$work"
"$sac" "$@" --set sac.eval_episodes="$episodes" --quiet --out "$work/run"
"$eval" "$work/run" --episodes "$episodes" --seed 1000000 --csv "$work/eval.csv"
python3 - "$work/run/metrics.csv" "$work/eval.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
sac_ret, sac_len = float(rows[-1]["eval_return"]), float(rows[-1]["eval_length"])
episodes = list(csv.DictReader(open(sys.argv[2])))
ev_ret = sum(float(e["return"]) for e in episodes) / len(episodes)
ev_len = sum(float(e["length"]) for e in episodes) / len(episodes)
same = abs(ev_ret - sac_ret) <= 1e-6 * max(1.0, abs(sac_ret)) and abs(ev_len - sac_len) <= 1e-6 * sac_len
print(f"{'SAME' if same else 'DIFFERENT'}: masa_sac's evaluation return {sac_ret:.7g} length {sac_len:.7g}, "
      f"masa_eval on policy.bin return {ev_ret:.7g} length {ev_len:.7g} over {len(episodes)} episodes")
sys.exit(0 if same else 1)
PY
