#!/usr/bin/env bash
# The fitcal container image, from Debian 12 packages and nothing else: mmdebstrap extracts
# fitcal's runtime libraries (RUNTIME_PACKAGES below, with their Debian dependencies) and busybox
# (the shell the Kubernetes Job's script runs in) into an empty root - no dpkg, apt or package
# database - adds the fitcal of the project's own Release build and deploy/k8s/fleet-index.sh,
# and umoci turns the root into an OCI archive tagged with the project's version.
#   tools/image/build.sh                      build-image/fitcal-<version>.oci.tar (fitcal:<version>)
#   tools/image/build.sh --smoke              the same, then the archive unpacked and, in it
#                                             (chroot), fitcal fit on data/flower compared with the
#                                             host's and the Job's script for that one robot
#   tools/image/build.sh --root DIR [--smoke] only the root, in DIR (must not exist), and the
#                                             smoke test in it (it leaves its files in DIR/fleet)
#   tools/image/build.sh --check-packages BIN RUNTIME_PACKAGES against the libraries BIN needs
#   --binary FILE                             this fitcal instead of a build in build-image/
# Runs as root (or where mmdebstrap's unshare mode works) on Debian 12, the Debian the binary is
# built for; installs mmdebstrap and umoci when missing. Package lists and packages are kept in
# build-image/apt-cache (FITCAL_IMAGE_CACHE): with it warm, only the archives' signed release
# files are downloaded again. docs/image.md has the figures.
set -euo pipefail
caller_dir=$PWD
cd "$(dirname "$0")/../.."

# The packages owning the libraries fitcal names (DT_NEEDED): ctest image_packages_check fails
# when the binary needs another or one here is no longer needed. Ceres is linked statically
# (libceres-dev's libceres.a), so its libraries are here and libceres3 is not; BLAS and LAPACK are
# ATLAS's (libatlas3-base), the alternative libceres-dev's dependencies install. Their own
# libraries (gflags, libunwind, SuiteSparse's, gfortran, ...) come as Debian dependencies.
RUNTIME_PACKAGES=(libc6 libgcc-s1 libstdc++6 libgoogle-glog0v6 libspqr2 libcholmod3 libcxsparse3
                  libatlas3-base libnlopt0 libyaml-cpp0.7 libsqlite3-0 libzstd1 liblz4-1
                  libfastcdr1)
SUITE=bookworm

die() { echo "tools/image/build.sh: $*" >&2; exit 1; }

# A path given on the command line, relative to where the script was started.
absolute() { (cd "$caller_dir" && realpath -m "$1"); }

version() { sed -n 's/^project(fitcal VERSION \([0-9.]*\).*/\1/p' CMakeLists.txt; }

# The Debian packages owning the libraries the binary names (DT_NEEDED), as the loader resolves
# them. dpkg knows the files by the path their package ships: the link's target (an alternative
# such as libblas.so.3 is a link no package owns), and on merged /usr that path may be /lib/...
needed_packages() {
  local binary=$1 libraries soname path real files=() owners
  libraries=$(ldd "$binary") || die "$binary: ldd failed"
  for soname in $(objdump -p "$binary" | awk '$1 == "NEEDED" { print $2 }'); do
    path=$(awk -v so="$soname" '$1 == so && $2 == "=>" { print $3 }' <<< "$libraries")
    [ -n "$path" ] && [ "$path" != "not" ] || die "$binary: $soname not found by the loader"
    files+=("$(readlink -f "$path")")
  done
  owners=$(dpkg -S "${files[@]}" "${files[@]#/usr}" 2> /dev/null) || true
  for real in "${files[@]}"; do
    path=$(awk -F': ' -v a="$real" -v b="${real#/usr}" '$2 == a || $2 == b { print $1; exit }' \
      <<< "$owners")
    [ -n "$path" ] || die "$real: owned by no Debian package"
    echo "${path%%:*}"
  done | sort -u
}

check_packages() {
  local binary=$1 needed listed status=0
  needed=$(needed_packages "$binary")
  listed=$(printf '%s\n' "${RUNTIME_PACKAGES[@]}" | sort -u)
  for p in $(comm -23 <(echo "$needed") <(echo "$listed")); do
    echo "$binary needs a library of $p: add it to RUNTIME_PACKAGES in tools/image/build.sh"
    status=1
  done
  for p in $(comm -13 <(echo "$needed") <(echo "$listed")); do
    echo "RUNTIME_PACKAGES lists $p, whose libraries $binary does not need: remove it"
    status=1
  done
  [ "$status" -ne 0 ] || echo "RUNTIME_PACKAGES = the owners of $binary's libraries: $(echo $needed)"
  return "$status"
}

install_tools() {
  local missing=()
  command -v mmdebstrap > /dev/null || missing+=(mmdebstrap)
  command -v umoci > /dev/null || missing+=(umoci)
  [ "${#missing[@]}" -eq 0 ] && return
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo=sudo
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

# The project's own Release build of fitcal alone, in its own directory, with CI's flags and ccache
# as tools/test.sh (so a machine that ran the tests compiles little).
build_binary() {
  local launcher=()
  if command -v ccache > /dev/null; then
    export CCACHE_BASEDIR="$PWD"
    export CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  fi
  cmake -S . -B build-image/build -G Ninja -DCMAKE_BUILD_TYPE=Release -DFITCAL_WERROR=ON \
    -DFITCAL_BUILD_TESTS=OFF -DFITCAL_BUILD_BENCHMARKS=OFF "${launcher[@]}" > /dev/null
  cmake --build build-image/build --target fitcal > /dev/null
  echo build-image/build/tools/fitcal
}

# The root: the packages extracted (no maintainer scripts run, so the two links the ATLAS
# package's postinst would make with update-alternatives are made here), busybox's applets as
# links (sh, mkdir, sed, ...), fitcal stripped, the Job's script.
build_root() {
  local binary=$1 root=$2 cache=${FITCAL_IMAGE_CACHE:-$PWD/build-image/apt-cache}
  [ ! -e "$root" ] || die "$root exists; the root is built into a new directory"
  mkdir -p "$cache/archives" "$cache/lists"
  local multiarch=/usr/lib/x86_64-linux-gnu
  local includes
  includes=$(IFS=,; echo "busybox,${RUNTIME_PACKAGES[*]}")
  mmdebstrap --variant=extract --include="$includes" --quiet \
    --setup-hook='mkdir -p "$1"/var/cache/apt/archives "$1"/var/lib/apt/lists' \
    --setup-hook="sync-in $cache/archives /var/cache/apt/archives" \
    --setup-hook="sync-in $cache/lists /var/lib/apt/lists" \
    --extract-hook="sync-out /var/cache/apt/archives $cache/archives" \
    --extract-hook="sync-out /var/lib/apt/lists $cache/lists" \
    --extract-hook='mkdir -p "$1"/sbin "$1"/usr/bin "$1"/usr/sbin' \
    --extract-hook='chroot "$1" /bin/busybox --install -s' \
    --extract-hook="ln -s atlas/libblas.so.3 \"\$1\"$multiarch/libblas.so.3" \
    --extract-hook="ln -s atlas/liblapack.so.3 \"\$1\"$multiarch/liblapack.so.3" \
    "$SUITE" "$root"
  install -D -m 0755 "$binary" "$root/usr/bin/fitcal"
  strip --strip-unneeded "$root/usr/bin/fitcal"
  install -D -m 0644 deploy/k8s/fleet-index.sh "$root/usr/share/fitcal/fleet-index.sh"
  # What mmdebstrap leaves for apt and dpkg, which the image does not have.
  rm -rf "$root/etc/apt" "$root/etc/dpkg" "$root/var/cache/apt" "$root/var/lib/apt" \
    "$root/var/lib/dpkg" "$root/var/log"
}

# The OCI layout of the root as one layer, named fitcal:<version> (podman load -i names it
# localhost/fitcal:<version>), tarred into one archive.
build_archive() {
  local root=$1 archive=$2 version=$3 layout tag
  layout=$(mktemp -d build-image/layout.XXXXXX)
  rmdir "$layout"
  tag=fitcal:$version
  umoci init --layout "$layout"
  umoci new --image "$layout:$tag"
  umoci insert --image "$layout:$tag" --history.created_by "tools/image/build.sh" "$root" /
  umoci config --image "$layout:$tag" --config.entrypoint /usr/bin/fitcal \
    --config.env PATH=/usr/local/bin:/usr/bin:/bin --config.workingdir / \
    --config.label org.opencontainers.image.title=fitcal \
    --config.label org.opencontainers.image.version="$version" \
    --author "fitcal tools/image/build.sh"
  umoci gc --layout "$layout"
  tar -C "$layout" -cf "$archive" .
  rm -rf "$layout"
}

# In a root (the archive as a runtime unpacks it, or --root's), under chroot: the fit of the
# shipped flower data set must write the calibration the host's fitcal writes from the same files
# (byte for byte: same source, same Debian libraries), and the Job's script, run for that one
# robot, a calibration, its report and the summary.
smoke() {
  local rootfs=$1 binary=$2 dir start=$SECONDS
  dir=$(mktemp -d build-image/smoke.XXXXXX)
  mkdir -p "$rootfs/fleet/data" "$rootfs/tmp"
  cp -r data/flower "$rootfs/fleet/data/flower"
  echo data/flower > "$rootfs/fleet/datasets.txt"
  chroot "$rootfs" /usr/bin/fitcal fit --logs /fleet/data/flower --out /fleet/image.yaml
  echo "smoke: fit in the image: $((SECONDS - start)) s"
  "$binary" fit --logs "$rootfs/fleet/data/flower" --out "$dir/host.yaml" > /dev/null
  diff <(grep -v '^  dataset:' "$rootfs/fleet/image.yaml") <(grep -v '^  dataset:' "$dir/host.yaml") \
    || die "the image's calibration differs from the host's"
  for index in 0 1; do
    chroot "$rootfs" /usr/bin/env JOB_COMPLETION_INDEX=$index RUN_ID=smoke RUN_DATE=2026-01-01 \
      /bin/sh /usr/share/fitcal/fleet-index.sh > "$dir/index$index.txt" \
      || die "the Job's script, index $index: exit $? ($dir/index$index.txt)"
  done
  local result=$rootfs/fleet/results/flower/2026-01-01 summary=$rootfs/fleet/summary/2026-01-01.txt
  for f in "$result/cal.yaml" "$result/report/metrics.json" "$summary"; do
    [ -s "$f" ] || die "the Job's script left no $f"
  done
  grep -q '^apr02$' "$summary" || die "$summary: no table for the robot apr02"
  echo "smoke: passed in $((SECONDS - start)) s (the image's calibration is the host's; the Job's script" \
    "wrote cal.yaml, report/metrics.json and the summary)"
  rm -rf "$dir"
}

smoke_archive() {
  local archive=$1 version=$2 binary=$3 dir
  dir=$(mktemp -d build-image/unpacked.XXXXXX)
  mkdir "$dir/layout"
  tar -C "$dir/layout" -xf "$archive"
  umoci unpack --image "$dir/layout:fitcal:$version" "$dir/bundle" > /dev/null
  smoke "$dir/bundle/rootfs" "$binary"
  rm -rf "$dir"
}

main() {
  local binary="" root="" smoke_test=0 version archive
  while [ $# -gt 0 ]; do
    case $1 in
      --binary) binary=$(absolute "$2"); shift 2 ;;
      --root) root=$(absolute "$2"); shift 2 ;;
      --smoke) smoke_test=1; shift ;;
      --check-packages) check_packages "$(absolute "$2")"; return ;;
      *) die "unknown argument $1 (see the comment at the top of this script)" ;;
    esac
  done
  [ "$smoke_test" -eq 0 ] || [ "$(id -u)" -eq 0 ] || die "--smoke runs the image under chroot: as root"
  version=$(version)
  [ -n "$version" ] || die "CMakeLists.txt: no project(fitcal VERSION ...)"
  install_tools
  mkdir -p build-image
  [ -n "$binary" ] || binary=$(build_binary)
  check_packages "$binary"
  if [ -n "$root" ]; then
    build_root "$binary" "$root"
    [ "$smoke_test" -eq 0 ] || smoke "$root" "$binary"
    return
  fi
  local start=$SECONDS
  root=$(mktemp -d build-image/root.XXXXXX)
  rmdir "$root"
  build_root "$binary" "$root"
  echo "root: $(du -sh "$root" | cut -f1), $((SECONDS - start)) s"
  archive=build-image/fitcal-$version.oci.tar
  build_archive "$root" "$archive" "$version"
  rm -rf "$root"
  echo "wrote $archive ($(du -h "$archive" | cut -f1), fitcal:$version), $((SECONDS - start)) s"
  [ "$smoke_test" -eq 0 ] || smoke_archive "$archive" "$version" "$binary"
}

main "$@"
