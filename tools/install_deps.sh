#!/usr/bin/env bash
# Installs fitcal's build and test dependencies from Debian 12 packages (run as root or with sudo).
#   tools/install_deps.sh [--tests]   --tests adds what only the test suite uses: Chromium, in which
#                                     page_render_test lays the report out at phone and desktop widths,
#                                     the npm packages of k8s_manifest_check (tests/k8s), and jq,
#                                     which a documented command runs (docs_commands_test)
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
PACKAGES=(build-essential cmake ninja-build pkg-config lld ccache
          libceres-dev libeigen3-dev libnlopt-cxx-dev libnlopt-dev libyaml-cpp-dev libcli11-dev
          libgtest-dev libgmock-dev libbenchmark-dev
          libsqlite3-dev libzstd-dev liblz4-dev libfastcdr-dev)
if [ "${1:-}" = "--tests" ]; then
  PACKAGES+=(chromium jq)
  command -v npm > /dev/null || PACKAGES+=(nodejs npm)
fi
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
# The Kubernetes OpenAPI schemas (kubernetes-models) and a YAML parser, pinned by
# tests/k8s/package-lock.json (26 MB, ~30 s): installed into tests/k8s/node_modules when that lock
# changed, so ctest itself downloads nothing.
if [ "${1:-}" = "--tests" ]; then
  k8s=$(cd "$(dirname "$0")/../tests/k8s" && pwd)
  if ! cmp -s "$k8s/package-lock.json" "$k8s/node_modules/.fitcal-package-lock.json"; then
    npm ci --prefix "$k8s" --no-audit --no-fund --loglevel=error
    cp "$k8s/package-lock.json" "$k8s/node_modules/.fitcal-package-lock.json"
  fi
fi
