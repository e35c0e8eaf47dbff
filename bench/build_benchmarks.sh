#!/usr/bin/env bash
# Builds the benchmark programs into BUILD_DIR (default build/): they are not part of `all`, so the
# test command stays inside CI's budget. Sourced or run by the bench/*.sh scripts that run one.
#   bash bench/build_benchmarks.sh [BUILD_DIR]
set -euo pipefail
build=${1:-${MASA_BUILD_DIR:-build}}
# A prebuilt copy of the programs (bench/device_bundle.sh, for a machine without our packages).
[ -f "$build/PREBUILT" ] && { return 0 2> /dev/null || exit 0; }
[ -f "$build/CMakeCache.txt" ] || { echo "build_benchmarks.sh: no configured build in $build (run scripts/build.sh first)" >&2; exit 2; }
cmake --build "$build" --target benchmarks -j"$(nproc)" > "$build/benchmarks_build.log" 2>&1 ||
  { tail -n 30 "$build/benchmarks_build.log" >&2; echo "build_benchmarks.sh: building the benchmarks failed (log: $build/benchmarks_build.log)" >&2; exit 1; }
