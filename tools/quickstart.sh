#!/usr/bin/env bash
# Sets up a fresh Debian 12 machine and runs the main job: NR-SLAM over the simulated
# colonoscopy suite (data_manifests/paper-sim.json: sim-0 … sim-6 and lap-lobes at 640x480,
# deformable and rigid), rendering the sequences on first use, and prints the results table.
# Extra arguments go to nrslam_eval (e.g. --jobs 4, --set k=2, --sweep max_degree_D=3,5,10).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
./build/tools/nrslam_eval data_manifests/paper-sim.json --out runs/paper-sim --cache runs/cache "$@"
