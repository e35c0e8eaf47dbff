#!/usr/bin/env bash
# Installs the Debian packages (idempotent) and builds masa into build/ (Release).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
