#!/usr/bin/env bash
# One command: install dependencies, build with warnings as errors, run the whole test suite.
#   tools/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."
tools/install_deps.sh --tests
jobs=$(nproc)
start=$SECONDS

# The slowest build steps of a build directory, from ninja's own log (kept in the directory), so
# that the next slow step is visible in every CI log.
slowest_steps() {
  echo "slowest build steps in $1 (s):"
  # (sed, not head: head would close the pipe early and pipefail would end the script)
  awk 'NR > 1 { printf "%8.1f  %s\n", ($2 - $1) / 1000, $4 }' "$1/.ninja_log" | sort -rn | sed -n 1,10p
}

# ccache, when installed (install_deps.sh installs it), keeps compiled objects across clones of
# the repository on one machine: paths are taken relative to the clone, and the precompiled
# headers' defines and time stamps are allowed to differ. A fresh machine builds cold.
launcher=()
if command -v ccache > /dev/null; then
  export CCACHE_BASEDIR="$PWD"
  export CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime
  # The sanitizer build's instrumented objects carry debug lines (-g1), and ccache then hashes the
  # build directory too: without this another clone compiles them again (282 s on a warm machine).
  export CCACHE_NOHASHDIR=1
  # Depend mode: on a miss ccache takes the included files from the compiler's own -MD output
  # instead of running the preprocessor first (by default it preprocesses every missed file once
  # more, to look it up by its preprocessed text). A cold build misses everything: the 100 Release
  # translation units' preprocessing is ~38 s of CPU, the instrumented ones' ~4 s (docs/tests.md);
  # hits are direct either way.
  export CCACHE_DEPEND=1
  # The inode cache: ccache hashes every file a translation unit included, after a miss (depend
  # mode) and before a hit, and nearly every file includes a precompiled header of 130-157 MB -
  # ~0.7 s of CPU and ~35 k page faults a file, most of a hit's cost. With the inode cache a file
  # is hashed once and its hash kept by inode, size and time stamps (any change rehashes it):
  # the Release build from hits 88.9 -> 27.0 s of CPU, the sanitizer build 69.6 -> 28.0 s, a miss
  # ~0.5 s less (docs/tests.md). Debian 12's ccache (4.7.5) keeps it off by default after reports
  # of processes hanging on its process-shared locks (4.8 reworked them and turned it on), so
  # each run keeps it in a temporary directory of its own, shared with no other run.
  export CCACHE_INODECACHE=1
  CCACHE_TEMPDIR=$(mktemp -d)
  export CCACHE_TEMPDIR
  trap 'rm -rf "$CCACHE_TEMPDIR"' EXIT
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DFITCAL_WERROR=ON "${launcher[@]}"
cmake --build build -j "$jobs"
slowest_steps build
echo "release build: $((SECONDS - start)) s"
# The tests labelled sanitize run once, in the sanitizer build below: the same test objects and
# numeric core as here, io/ and the commands instrumented with their assertions on. Running them
# here too added 89 s of CPU (274 tests, 28f1b57) and no assertion; the -O3 io/ and commands are
# run here by the Release-only tests (approvals, documented commands, end-to-end fits).
# `ctest --test-dir build` without -LE still runs everything.
ctest --test-dir build --output-on-failure -j "$jobs" -LE sanitize
echo "release tests done: $((SECONDS - start)) s"

# Sanitizers by purpose: AddressSanitizer + UndefinedBehaviorSanitizer instrument the code that
# reads, parses and writes (io and the commands; CMakeLists.txt says why) and
# run the executables marked SANITIZE in tests/CMakeLists.txt (parsers, writers, the command line,
# the model harness), in their own build directory. Everything else compiles exactly as in the
# Release build above, so ccache hands it over instead of compiling it again.
# FITCAL_ASAN_BUILD_DIR lets a developer keep this build apart from others (default build-asan).
asan_dir=${FITCAL_ASAN_BUILD_DIR:-build-asan}
cmake -S . -B "$asan_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DFITCAL_SANITIZE=ON -DFITCAL_WERROR=ON \
  -DFITCAL_BUILD_BENCHMARKS=OFF "${launcher[@]}"
cmake --build "$asan_dir" -j "$jobs"
slowest_steps "$asan_dir"
echo "sanitizer build: $((SECONDS - start)) s"
# quarantine_size_mb=64 (256 by default): freed memory is held back from reuse so that a
# use-after-free finds it poisoned. At a quarter of the default a use is still caught while its
# block is among the last 64 MB freed, and a fit faults in fresh pages half as often (an OptiOdom
# diff drive: 109k -> 55k page faults, 1.5 -> 0.7 s of system time; docs/tests.md).
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:quarantine_size_mb=64 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir "$asan_dir" --output-on-failure -j "$jobs" -L sanitize
echo "tools/test.sh: $((SECONDS - start)) s"
# CPU time of the whole run (user, system; the shell, then its children): on a loaded machine the
# wall time above says little, this does not.
times
