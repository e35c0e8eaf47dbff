#!/usr/bin/env bash
# Prints the eval_return of the last row of a metrics.csv; fails when that column is missing, or
# is nan there (the learner evaluated nothing in its last update).
#   last_eval_return.sh RUN_DIR/metrics.csv
set -euo pipefail
awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "eval_return") c = i; next }
         { v = $c }
         END { if (!c || v == "" || v == "nan") { print "no eval_return in the last row"; exit 1 }
               print "last eval_return " v }' "$1"
