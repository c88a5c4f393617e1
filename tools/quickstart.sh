#!/usr/bin/env bash
# Sets up a fresh Debian 12 machine and runs the main job: renders the simulated suite
# (sim-0 … sim-6 and lap-lobes, 640x480, 120 frames) and prints its summary table.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
./build/tools/nrslam_simulate --suite --out runs/sim-suite "$@"
