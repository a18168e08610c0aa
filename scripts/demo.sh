#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The main job: install what is missing, build, and calibrate the shipped
# simulated data set (data/sim_irb120.csv) with a readable report, compared
# with the simulation's known truth; writes build/calibrated.json.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" >/dev/null
./build/tools/rcal calibrate --data data/sim_irb120.csv --truth data/sim_irb120_truth.json \
  --out build/calibrated.json "$@"
