#!/usr/bin/env bash
# One command: install dependencies, build, calibrate the shipped flower data set.
#   tools/run.sh [extra fitcal flags]
set -euo pipefail
cd "$(dirname "$0")/.."
tools/install_deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DFITCAL_BUILD_TESTS=OFF > build.log 2>&1 \
  || { cat build.log; exit 1; }
cmake --build build --target fitcal >> build.log 2>&1 || { cat build.log; exit 1; }
./build/tools/fitcal --logs data/flower --method ceres --out build/calibrated.yaml "$@"
