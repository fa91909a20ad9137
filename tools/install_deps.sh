#!/usr/bin/env bash
# Installs fitcal's build and test dependencies from Debian 12 packages (run as root or with sudo).
#   tools/install_deps.sh [--tests]   --tests adds what only the test suite uses: Chromium, in which
#                                     page_render_test lays the report out at phone and desktop widths,
#                                     and jq, which a documented command runs (docs_commands_test)
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
PACKAGES=(build-essential cmake ninja-build pkg-config mold ccache
          libceres-dev libeigen3-dev libnlopt-cxx-dev libnlopt-dev libyaml-cpp-dev libcli11-dev
          libgtest-dev libgmock-dev libbenchmark-dev
          libsqlite3-dev libzstd-dev liblz4-dev libfastcdr-dev)
if [ "${1:-}" = "--tests" ]; then PACKAGES+=(chromium jq); fi
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
