#!/usr/bin/env bash
# Installs the Debian 12 packages that only the comparison benchmarks need (LibTorch, OpenBLAS);
# see install_deps.sh --bench. Reconfigure the build afterwards to get bench_learner_step_libtorch.
set -euo pipefail
exec bash "$(dirname "$0")/install_deps.sh" --bench
