#!/usr/bin/env bash
# One command: install dependencies, build with warnings as errors, run the whole test suite.
#   tools/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."
tools/install_deps.sh
jobs=$(nproc)
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DFITCAL_WERROR=ON
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"

# The unit tests once more under AddressSanitizer + UndefinedBehaviorSanitizer (memory errors a Release run hides), in their
# own build directory; -O1 keeps the instrumented build and the Ceres fits fast enough for CI.
# FITCAL_ASAN_BUILD_DIR lets a developer keep this build apart from others (default build-asan).
asan_dir=${FITCAL_ASAN_BUILD_DIR:-build-asan}
cmake -S . -B "$asan_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DFITCAL_SANITIZE=ON -DFITCAL_WERROR=ON \
  -DFITCAL_BUILD_BENCHMARKS=OFF
cmake --build "$asan_dir" -j "$jobs"
# A test too slow under the sanitizers for CI can opt out with the ctest label no_sanitize.
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir "$asan_dir" --output-on-failure -j "$jobs" -LE no_sanitize
