#!/usr/bin/env bash
# Installs the Debian 12 packages that only the comparison benchmarks need (never CI, never a
# training run): LibTorch for bench/libtorch/ and OpenBLAS for its tuned set-up
# (bench/run_learner_vs_libtorch.sh). Idempotent, like install_deps.sh.
#
# Note: installing libopenblas0 makes OpenBLAS the system's libblas.so.3 (update-alternatives);
# masa itself links no BLAS, and the comparison script picks each set-up's BLAS explicitly.
set -euo pipefail

packages=(libtorch-dev libopenblas-dev)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_bench_deps: all ${#packages[@]} packages present."
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
echo "install_bench_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install_bench_deps: done; reconfigure the build to get bench_learner_step_libtorch."
