#!/usr/bin/env bash
# Installs the dependencies (if missing) and builds nrslam in Release into build/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install_deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
