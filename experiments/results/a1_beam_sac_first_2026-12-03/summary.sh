#!/usr/bin/env bash
# The tables of README.md from the runs' metrics.csv (SAC, this record) and the PPO recipe grid's
# (../a1_beam_grid_recipe_2026-12-02): for each run, the first environment step at which the mean
# return of the training episodes finished in a row passed 200, 500, 1000 and 2500, and the first
# evaluation of the policy mean that stood the whole 20 s (length 1000).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
ppo=$here/../a1_beam_grid_recipe_2026-12-02/a1_beam
echo "run | train >200 | >500 | >1000 | >2500 | first eval of 1000 steps (return) | last eval return, m"
for d in "$here"/sac_*; do
  awk -F, -v run="SAC $(basename "$d" | sed 's/^sac_//')" '
    NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
    { r = $col["train_return"]; if (r != "nan") for (k = 1; k <= 4; ++k) if (!hit[k] && r > t[k]) hit[k] = $1
      e = $col["eval_return"]; if (e != "nan") { last = sprintf("%.0f, %.1f m", e, $col["eval_distance_m"])
        if (!stood && $col["eval_length"] >= 1000) stood = sprintf("%d (%.0f)", $1, e) } }
    BEGIN { t[1] = 200; t[2] = 500; t[3] = 1000; t[4] = 2500 }
    END { printf "%s | %s | %s | %s | %s | %s | %s\n", run, hit[1] ? hit[1] : "-", hit[2] ? hit[2] : "-",
          hit[3] ? hit[3] : "-", hit[4] ? hit[4] : "-", stood ? stood : "-", last }' "$d/metrics.csv"
done
for m in masa sa; do
  for s in 0 1 2 3 4; do
    awk -F, -v run="PPO ${m}_s$s" '
      NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
      { r = $col["return"]; for (k = 1; k <= 4; ++k) if (!hit[k] && r > t[k]) hit[k] = $col["env_steps"]
        e = $col["eval_return"]; if (e != "nan" && e != "" && !stood && $col["eval_length"] >= 1000)
          stood = sprintf("%d (%.0f)", $col["env_steps"], e) }
      BEGIN { t[1] = 200; t[2] = 500; t[3] = 1000; t[4] = 2500 }
      END { printf "%s | %s | %s | %s | %s | %s | (9.83M steps)\n", run, hit[1], hit[2], hit[3], hit[4], stood ? stood : "-" }' \
      "$ppo/${m}_s$s/metrics.csv"
  done
done
