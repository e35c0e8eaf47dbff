#!/usr/bin/env bash
# An experiment grid: every task x method x seed trained with masa_train (learner and one actor in
# one process, deterministic per seed) from the task's recipe, as many runs at once as there are
# slots, then the comparison: figures, statistics and verdict of masa_compare (tools/compare.cpp).
#   experiments/grid.sh --tasks "a1_beam" --methods "masa sa sasa ma" --seeds "0 1 2 3 4" \
#       [--updates N] [--no-recipe | --recipe NAME] [--jobs N] [--threads T] [--hosts FILE] [--out DIR] [--set key=value ...]
#   experiments/grid.sh --replot --out DIR      (only the comparison of an existing grid)
#   experiments/grid.sh --extend N --out DIR    (the grid's runs go on to N updates each)
#   experiments/grid.sh --out DIR --seeds "0 ... 9"  (more seeds, methods or tasks: the grid grows)
#   experiments/grid.sh --status --out DIR      (each run's progress and the grid's ETA)
#   experiments/grid.sh --replot --out DIR --milestone eval_distance_m=5  (when each run first walks 5 m)
# Resumable: run the same command again (or with --out DIR) after a kill. A finished run (its
# `done` file) is not redone, a run with a checkpoint goes on from it, the rest start afresh.
# Runs are taken seed by seed, so a grid stopped early has whole seeds of every method.
# --extend N raises the grid's updates to N: every run goes on from its checkpoint and its
# environments (actor_state.bin), as after a kill; grid.txt records when and from how many.
# Results: DIR/<task>/<method>_s<seed>/ (run directories: config.yaml, metrics.csv, policy.bin, ...,
# and <method>_s<seed>.log), DIR/grid.txt (the grid), DIR/<task>/compare*.png and verdict.md.
# --hosts FILE: one line per host, "name [slots]" ("localhost" runs here). Remote hosts need this
# checkout, built, at the same path; the run directory is copied there before and back after each
# run (MASA_SSH and MASA_RSYNC choose the commands, default ssh and rsync).
# --milestone [TASK:]COLUMN=LEVEL (repeatable): the verdict adds when each run's COLUMN (a metrics.csv
# column, e.g. an evaluation figure) first reaches LEVEL (COLUMN<=LEVEL: first falls to it, for an
# error); kept in grid.txt, it can be added to a grid at any time (a rerun or --replot) without
# changing its runs.
# --recipe NAME: every run from configs/recipes/NAME.yaml (or that YAML file) instead of its task's
# recipe, e.g. --recipe a1_beam_off_policy; --no-recipe: from the task's config alone.
# MASA_BUILD_DIR chooses the build (default build).
set -euo pipefail
caller=$(pwd)
cd "$(dirname "$0")/.."
source experiments/job_queue.sh
repo=$(pwd)
# --out and --hosts are the caller's paths; MASA_BUILD_DIR is relative to the checkout.
abs() { case "$1" in /*) echo "$1" ;; *) echo "$caller/$1" ;; esac; }

tasks="" methods="" seeds="" updates="" jobs="" threads=1 out="" hosts="" sets=() replot=0 recipe=1 recipe_given="" extend="" grown=()
milestones=()
status=0
while [ $# -gt 0 ]; do
  case "$1" in
    --tasks) tasks=$2; shift 2 ;;
    --methods) methods=$2; shift 2 ;;
    --seeds) seeds=$2; shift 2 ;;
    --updates) updates=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --hosts) hosts=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --set) sets+=("$2"); shift 2 ;;
    --milestone) milestones+=("$2"); shift 2 ;;
    --no-recipe) recipe_given=0; shift ;;
    --recipe) recipe_given=$2; shift 2 ;;
    --replot) replot=1; shift ;;
    --extend) extend=$2; shift 2 ;;
    --status) status=1; shift ;;
    -h|--help) awk 'NR > 1 && !/^#/ { exit } NR > 1' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;  # the header, whole
    *) echo "grid.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
for x in "${milestones[@]+"${milestones[@]}"}"; do
  [[ "$x" =~ ^([A-Za-z0-9_]+:)?[A-Za-z0-9_]+(=|\<=|\>=)[-+]?[0-9.]+([eE][-+]?[0-9]+)?$ ]] || \
    { echo "grid.sh: --milestone '$x': write [TASK:]COLUMN=LEVEL, e.g. eval_distance_m=5 (COLUMN<=LEVEL for an error)" >&2; exit 2; }
done
[ ${#milestones[@]} -eq 0 ] || [ "$status" = 0 ] || { echo "grid.sh: --status only reads; give --milestone with --replot" >&2; exit 2; }
[ -n "$out" ] && out=$(abs "$out")
# The recipe: 1 = each task's own (configs/recipes/<task>.yaml), 0 = none, else one recipe for all
# (a name of configs/recipes/ or a YAML file, kept as an absolute path).
if [ -n "$recipe_given" ] && [ "$recipe_given" != 0 ]; then
  if [ -f "$(abs "$recipe_given")" ]; then recipe_given=$(abs "$recipe_given")
  elif [[ "$recipe_given" =~ ^[A-Za-z0-9_]+$ ]] && [ -f "configs/recipes/$recipe_given.yaml" ]; then :
  else echo "grid.sh: --recipe '$recipe_given': no configs/recipes/$recipe_given.yaml and no such file" >&2; exit 2
  fi
fi
[ -n "$hosts" ] && hosts=$(abs "$hosts")
build=${MASA_BUILD_DIR:-build}
[ -x "$build/tools/masa_train" ] || { echo "grid.sh: $build/tools/masa_train is missing: run scripts/build.sh first" >&2; exit 2; }
# The comparison: the build's masa_compare, else this checkout's (a frozen build may hold only
# masa_train; masa_compare reads the metrics.csv of runs of any commit).
compare=$build/tools/masa_compare
if [ ! -x "$compare" ] && [ -x build/tools/masa_compare ]; then
  [ "$status" = 1 ] || echo "grid.sh: $build has no masa_compare: the comparison will use this checkout's build/tools/masa_compare" >&2
  compare=build/tools/masa_compare
fi

# --extend: the grid in DIR, locked like a running grid (see below), gets the new number of
# updates, and its finished runs lose their `done` marks; the rest is a resume.
if [ -n "$extend" ]; then
  [ -n "$out" ] && [ -f "$out/grid.txt" ] || { echo "grid.sh: --extend needs --out with an existing grid (its grid.txt)" >&2; exit 2; }
  [[ "$extend" =~ ^[1-9][0-9]*$ ]] || { echo "grid.sh: --extend takes a number of updates, not '$extend'" >&2; exit 2; }
  if [ -n "$tasks$methods$seeds$updates" ] || [ ${#sets[@]} -gt 0 ] || [ ${#milestones[@]} -gt 0 ] || [ "$replot" = 1 ]; then
    echo "grid.sh: --extend changes only the updates of the grid in --out: give it no other grid options" >&2; exit 2
  fi
  have=$(sed -n 's/^updates=//p' "$out/grid.txt")
  [ -n "$have" ] || { echo "grid.sh: $out's runs follow each recipe's length (ppo.max_updates, or sac.env_steps off-policy; no --updates); --extend needs a number to go on from" >&2; exit 2; }
  [ "$extend" -gt "$have" ] || { echo "grid.sh: $out's runs already go to $have updates; --extend $extend must be more" >&2; exit 2; }
  # A finished run goes on only from its checkpoint; without one (a record made without them) it
  # would start afresh and lose its updates, so the extension is refused before anything changes.
  bare=$(find "$out" -mindepth 3 -maxdepth 3 -name done -printf '%h\n' | sort | while read -r d; do
           [ -f "$d/checkpoint.bin" ] || echo "${d#"$out"/}"; done)
  if [ -n "$bare" ]; then
    echo "grid.sh: --extend needs each finished run's checkpoint, and these have none: $(echo $bare)" \
         "(a record keeps them with record_grid.sh --all-checkpoints)" >&2; exit 2
  fi
  exec {grid_lock}> "$out/.grid.lock"
  flock -n "$grid_lock" || { echo "grid.sh: another grid is running in $out (wait for it, or stop it first)" >&2; exit 3; }
  sed -i "s/^updates=.*/updates=$extend/" "$out/grid.txt"
  echo "# extended from $have to $extend updates $(date -u +%FT%TZ) at commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown)" >> "$out/grid.txt"
  find "$out" -mindepth 3 -maxdepth 3 -name done -delete
  echo "grid.sh: $out extended from $have to $extend updates a run"
fi

# The grid's definition is kept in DIR/grid.txt: a rerun with --out DIR and no grid options
# continues it, and a rerun that names a different grid for the same DIR is refused.
if [ -n "$out" ] && [ -f "$out/grid.txt" ]; then
  # shellcheck disable=SC1091
  saved=$(cat "$out/grid.txt")
  g_tasks=$(sed -n 's/^tasks=//p' <<< "$saved"); g_methods=$(sed -n 's/^methods=//p' <<< "$saved")
  g_seeds=$(sed -n 's/^seeds=//p' <<< "$saved"); g_updates=$(sed -n 's/^updates=//p' <<< "$saved")
  g_recipe=$(sed -n 's/^recipe=//p' <<< "$saved"); g_sets=$(sed -n 's/^set=//p' <<< "$saved")
  # Naming all the grid has and more (seeds, methods, tasks) grows it: its runs stay, the new ones
  # join the queue. The same ones in another order are the grid as it is. Anything else that
  # differs is another grid.
  words() { tr -s ' ' '\n' <<< "$1" | sed '/^$/d' | sort -u; }
  for k in tasks methods seeds updates; do
    want=${!k}; have=$(eval echo "\$g_$k")
    { [ -z "$want" ] || [ "$want" = "$have" ]; } && continue
    if [ "$k" != updates ] && [ -z "$(comm -23 <(words "$have") <(words "$want"))" ]; then
      if [ -z "$(comm -13 <(words "$have") <(words "$want"))" ]; then printf -v "$k" '%s' "$have"; continue; fi
      grown+=("$k '$have' -> '$want'"); continue
    fi
    echo "grid.sh: $out is the grid $k='$have', not '$want' (use another --out; to grow it, name all it has and more)" >&2
    exit 2
  done
  if [ ${#grown[@]} -gt 0 ] && { [ "$replot" = 1 ] || [ "$status" = 1 ]; }; then
    echo "grid.sh: --replot and --status take the grid as it is; growing it (${grown[*]}) runs the new runs" >&2; exit 2
  fi
  if [ ${#sets[@]} -gt 0 ] && [ "$(printf '%s\n' "${sets[@]}")" != "$g_sets" ]; then
    echo "grid.sh: $out was made with other --set options:"$'\n'"$g_sets" >&2; exit 2
  fi
  if [ -n "$recipe_given" ] && [ "$recipe_given" != "$g_recipe" ]; then
    echo "grid.sh: $out was made with recipe=$g_recipe, not '$recipe_given' (1: each task's own, 0: none)" >&2; exit 2
  fi
  tasks=${tasks:-$g_tasks} methods=${methods:-$g_methods} seeds=${seeds:-$g_seeds} updates=$g_updates recipe=$g_recipe
  mapfile -t sets < <(printf '%s' "$g_sets" | sed '/^$/d')
elif [ "$replot" = 1 ] || [ "$status" = 1 ]; then
  echo "grid.sh: --replot and --status need --out with an existing grid (its grid.txt)" >&2; exit 2
else
  tasks=${tasks:-a1_beam} methods=${methods:-masa sa} seeds=${seeds:-0} recipe=${recipe_given:-1}
  out=${out:-experiments/results/grid_$(date +%Y%m%d_%H%M%S)}
  mkdir -p "$out"
  { echo "tasks=$tasks"; echo "methods=$methods"; echo "seeds=$seeds"; echo "updates=$updates"
    echo "recipe=$recipe"; for x in "${sets[@]+"${sets[@]}"}"; do echo "set=$x"; done
    for x in "${milestones[@]+"${milestones[@]}"}"; do echo "milestone=$x"; done
    echo "# started $(date -u +%FT%TZ) at commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
  } > "$out/grid.txt"
  milestones=()
fi
out=$(cd "$out" && pwd)
# The recipe file of task $1's runs, or nothing.
recipe_file() {
  case "$recipe" in
    0) ;;
    1) [ ! -f "configs/recipes/$1.yaml" ] || echo "configs/recipes/$1.yaml" ;;
    /*) echo "$recipe" ;;
    *) echo "configs/recipes/$recipe.yaml" ;;
  esac
}

# --status: every run's updates against its target, its last evaluation return (the policy mean's,
# runner.eval_every), and the grid's ETA from each method's recent
# seconds per update (the mean over its runs of the median of their last 50 updates) at the grid's
# slots (those of the running grid, else one per core). Reads only; a running grid goes on.
if [ "$status" = 1 ]; then
  running=0
  ( flock -n 9 ) 9> "$out/.grid.lock" || running=1
  slots_now=$( [ "$running" = 1 ] && [ -f "$out/.slots" ] && wc -l < "$out/.slots" || nproc)
  remote_slots=$( [ -f "$out/.slots" ] && grep -cvx localhost "$out/.slots" || true)
  echo "grid $out: $tasks / $methods / seeds $seeds, ${updates:-the recipe max_updates} updates a run;" \
       "$( [ "$running" = 1 ] && echo "running, $slots_now at a time" || echo "not running")"
  for t in $tasks; do for m in $methods; do for sd in $seeds; do
    dir="$out/$t/${m}_s$sd" target=$updates
    # The updates (or off-policy rounds) the run's own config asks for, else its recipe's.
    [ -n "$target" ] || [ ! -f "$dir/config.yaml" ] ||
      target=$("$build/tools/masa_config" --run-config "$dir/config.yaml" --rollout 2>/dev/null | sed -n 's/^max_updates: //p')
    rf=$(recipe_file "$t")
    [ -n "$target" ] || [ -z "$rf" ] || target=$("$build/tools/masa_config" --set "@$rf" --rollout 2>/dev/null | sed -n 's/^max_updates: //p')
    state=waiting age=0
    if [ -f "$dir/done" ]; then state=done
    elif [ -f "$dir/metrics.csv" ]; then
      state=stopped age=$(( $(date +%s) - $(stat -c %Y "$dir/metrics.csv") ))
      # On this machine a run is running exactly when its masa_train is; elsewhere (--hosts) awk judges by age.
      if [ "$running" = 1 ] && [ "$remote_slots" = 0 ]; then
        pgrep -f -- "--run-dir $(realpath "$dir")( |\$)" > /dev/null && state=running
        age=999999
      fi
    fi
    echo "$t $m $sd ${target:-0} $state $dir/metrics.csv $age"
  done; done; done | awk -v slots="$slots_now" -v grid_running="$running" '
    { run[NR] = $0; t[NR] = $1; m[NR] = $2; s[NR] = $3; target[NR] = $4; state[NR] = $5; rows = 0; spu = ""
      if ($5 != "waiting") {
        n = 0
        ev = ""; col = 0; wc = 0  # the last evaluation of the policy mean (eval_return); the wall clock (wall_time_s)
        while ((getline line < $6) > 0) {
          nf = split(line, f, ",")
          if (n == 0) { for (c = 1; c <= nf; c++) { if (f[c] == "eval_return") col = c; if (f[c] == "wall_time_s") wc = c } }
          else { w[n] = f[wc]; if (col > 0 && f[col] != "" && f[col] != "nan") ev = f[col] }
          n++
        }
        close($6); rows = n - 1
        k = rows > 50 ? 50 : rows - 1
        if (k > 0) {  # the median of the last k updates: a pause (a session break, SIGSTOP) does not count
          for (j = 1; j <= k; j++) {
            d = w[rows - j + 1] - w[rows - j]
            for (q = j - 1; q >= 1 && dd[q] > d; q--) dd[q + 1] = dd[q]
            dd[q + 1] = d
          }
          spu = k % 2 ? dd[(k + 1) / 2] : (dd[k / 2] + dd[k / 2 + 1]) / 2
          sum[$1 " " $2] += spu; cnt[$1 " " $2]++; all += spu; nall++
        }
      }
      # A run of a running grid is running while its metrics.csv grows: a row within 5 of its updates
      # (2 minutes at least, 5 before it has a speed); older, it was stopped (a grid stopped and started
      # again goes on with other runs first).
      if (state[NR] == "stopped" && grid_running == 1 && $7 < (spu == "" ? 300 : (5 * spu > 120 ? 5 * spu : 120)))
        state[NR] = "running"
      done_rows[NR] = rows; speed[NR] = spu; last_eval[NR] = $5 == "waiting" ? "" : ev; count[state[NR]]++ }
    END {
      total = 0; left = 0; eta = 0
      for (i = 1; i <= NR; i++) {
        key = t[i] " " m[i]
        per = cnt[key] > 0 ? sum[key] / cnt[key] : (nall > 0 ? all / nall : 0)
        remaining = target[i] - done_rows[i]; if (remaining < 0) remaining = 0
        total += target[i]; left += remaining; eta += remaining * per
        printf "  %-20s %-6s seed %-3s %7d/%-7d %-8s %-14s %s\n", t[i], m[i], s[i], done_rows[i], target[i], state[i],
               speed[i] == "" ? "" : sprintf("%.2f s/update", speed[i]),
               last_eval[i] == "" ? "" : sprintf("last eval %.1f", last_eval[i])
      }
      pct = total > 0 ? 100 * (total - left) / total : 0
      h = eta / (slots > 0 ? slots : 1) / 3600
      printf "%d done, %d running, %d stopped, %d waiting; %d of %d updates (%.0f%%); ", count["done"], count["running"],
             count["stopped"], count["waiting"], total - left, total, pct
      if (nall > 0) printf "ETA %d:%02d h at %d run%s at a time\n", int(h), int((h - int(h)) * 60 + 0.5), slots,
                           slots == 1 ? "" : "s"
      else printf "no run has measured its speed yet\n"
    }'
  exit 0
fi

# One grid per directory: a second one (a command given twice) would start the same runs afresh
# over the first's. The lock is held until this script exits.
if [ -z "$extend" ]; then
  exec {grid_lock}> "$out/.grid.lock"
  if ! flock -n "$grid_lock"; then
    echo "grid.sh: another grid is running in $out (wait for it, or stop it first)" >&2
    exit 3
  fi
fi
# A milestone whose column the grid's runs so far do not have is refused before anything changes.
for x in "${milestones[@]+"${milestones[@]}"}"; do
  t=${x%%=*}; t=${t%[<>]}; column=${t#*:}; t=${t%"$column"}; t=${t%:}  # [TASK:]COLUMN before =, <= or >=
  headers=$(for f in "$out"/${t:-*}/*_s*/metrics.csv; do [ ! -f "$f" ] || head -n 1 "$f"; done)
  [ -z "$headers" ] || tr ',' '\n' <<< "$headers" | grep -qxF "$column" || \
    { echo "grid.sh: --milestone $x: the runs of $out${t:+ ($t)} have no column '$column'" >&2; exit 2; }
done
# A grid that grows writes its new definition only under the lock: a running grid's never changes.
if [ ${#grown[@]} -gt 0 ]; then
  for k in tasks methods seeds; do sed -i "s/^$k=.*/$k=${!k}/" "$out/grid.txt"; done
  echo "# grew: ${grown[*]} $(date -u +%FT%TZ) at commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown)" >> "$out/grid.txt"
  echo "grid.sh: $out grows: ${grown[*]}"
fi
# New milestones join the grid's (masa_compare reads them from grid.txt); its runs do not change.
for x in "${milestones[@]+"${milestones[@]}"}"; do
  grep -qxF "milestone=$x" "$out/grid.txt" && continue
  echo "milestone=$x" >> "$out/grid.txt"
  echo "grid.sh: $out compares milestone $x"
done

if [ "$replot" = 0 ]; then
  # The queue: one line per run, seeds outermost. Workers take lines under a lock.
  queue="$out/.queue" lock="$out/.queue.lock"
  : > "$queue"
  total=0 finished=0
  for s in $seeds; do for t in $tasks; do for m in $methods; do
    total=$((total + 1))
    if [ -f "$out/$t/${m}_s$s/done" ]; then finished=$((finished + 1)); else echo "$t $m $s" >> "$queue"; fi
  done; done; done
  # Slots: one "host" line per slot.
  slots="$out/.slots"
  if [ -n "$hosts" ]; then
    [ -f "$hosts" ] || { echo "grid.sh: no hosts file $hosts" >&2; exit 2; }
    awk '!/^[[:space:]]*(#|$)/ { n = ($2 == "" ? 1 : $2); for (i = 0; i < n; ++i) print $1 }' "$hosts" > "$slots"
  else
    jobs=${jobs:-$(( $(nproc) / threads > 0 ? $(nproc) / threads : 1 ))}
    for ((i = 0; i < jobs; ++i)); do echo localhost; done > "$slots"
  fi
  echo "grid.sh: $total runs ($tasks / $methods / seeds $seeds), $finished already done," \
       "$(wc -l < "$slots") at a time, into $out"

  export build repo out updates recipe threads queue lock
  export MASA_GRID_SETS; MASA_GRID_SETS=$(printf '%s\n' "${sets[@]+"${sets[@]}"}")
  # One run: fresh, or resumed from its checkpoint. `done` is written only when the run reached its
  # target (masa_train exits 0 on SIGTERM too, after its checkpoint).
  run_one() {
    local host=$1 t=$2 m=$3 s=$4 dir="$out/$2/$3_s$4"
    local log="$dir.log" args=(--quiet --threads "$threads")
    [ -n "$updates" ] && args+=(--updates "$updates")
    if [ -f "$dir/checkpoint.bin" ] && [ -f "$dir/config.yaml" ]; then
      args+=(--resume "$dir")
    else
      rm -rf "$dir"
      args+=(--run-dir "$dir")
      local r; r=$(recipe_file "$t"); [ -z "$r" ] || args+=(--recipe "$r")
      args+=(--set task="$t" --set method="$m" --set seed="$s")
      while IFS= read -r x; do [ -n "$x" ] && args+=(--set "$x"); done <<< "$MASA_GRID_SETS"
    fi
    local cmd; cmd="cd $(printf '%q' "$repo") && OMP_NUM_THREADS=$threads $(printf '%q ' "$build/tools/masa_train" "${args[@]}")"
    local rc=0
    echo "# $(date -u +%FT%TZ) on $host: $cmd" >> "$log"
    # Which code: binaries from before --version existed say nothing, and the log says so.
    echo "# binaries: masa $("$build/tools/masa_train" --version 2> /dev/null || echo "of unknown commit (no --version)")" >> "$log"
    if [ "$host" = localhost ]; then
      bash -c "$cmd" >> "$log" 2>&1 || rc=$?
    else
      local ssh=${MASA_SSH:-ssh} rsync=${MASA_RSYNC:-rsync}
      $ssh "$host" "mkdir -p $(printf '%q' "$dir")" && \
        { [ ! -d "$dir" ] || $rsync -a "$dir/" "$host:$dir/"; } && \
        $ssh "$host" "$cmd" >> "$log" 2>&1 || rc=$?
      $rsync -a "$host:$dir/" "$dir/" || rc=$?
    fi
    # Done when the last line's update count equals the first line's target.
    local target reached
    target=$(sed -n 's/^masa_train: .* \([0-9][0-9]*\) updates, run dir .*/\1/p' "$log" | tail -1)
    reached=$(sed -n 's/^masa_train: \([0-9][0-9]*\) updates, [0-9]* env steps; .*/\1/p' "$log" | tail -1)
    if [ "$rc" = 0 ] && [ -n "$target" ] && [ "$reached" = "$target" ]; then
      touch "$dir/done"; echo "grid.sh: done $t $m seed $s ($reached updates, $host)"
      # The grid's progress and ETA after each finished run (the summary line of --status).
      echo "grid.sh: $(bash "$repo/experiments/grid.sh" --status --out "$out" 2>/dev/null | tail -n 1)"
    elif [ "$rc" = 0 ]; then
      echo "grid.sh: stopped $t $m seed $s at ${reached:-?} of ${target:-?} updates (a rerun resumes it)"
    else
      echo "grid.sh: FAILED $t $m seed $s on $host (exit $rc, see $log)"
    fi
  }
  worker() {
    local host=$1 line
    while :; do
      line=$(pop_job "$queue" "$lock")
      [ -n "$line" ] || return 0
      # shellcheck disable=SC2086
      run_one "$host" $line
    done
  }
  export -f run_one worker pop_job recipe_file
  for t in $tasks; do mkdir -p "$out/$t"; done
  pids=()
  # On a kill: the workers (no new runs) and their runs, which checkpoint and exit; the grid exits
  # after them, so that a rerun never meets a run still writing.
  stop_all() { stop_workers "grid.sh: stopped; run the same command again (or grid.sh --out $out) to go on" "${pids[@]}"; }
  trap stop_all INT TERM
  while read -r host; do bash -c 'worker "$0"' "$host" & pids+=($!); done < "$slots"
  wait "${pids[@]}"
  rm -f "$queue" "$lock" "$slots"
fi

[ -x "$compare" ] || { echo "grid.sh: no masa_compare in $build or build/: the runs are done; build it (scripts/build.sh) and draw the comparison with grid.sh --replot --out $out" >&2; exit 1; }
"$compare" "$out"
