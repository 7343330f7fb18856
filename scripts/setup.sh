#!/usr/bin/env bash
# Shared set-up for scripts/demo and scripts/test: installs the Debian
# packages domel needs (when missing; needs root or sudo), then configures
# and builds into ./build. Sourced, not run.
set -euo pipefail

DOMEL_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${DOMEL_BUILD_DIR:-$DOMEL_ROOT/build}"
JOBS="${DOMEL_JOBS:-$(nproc 2>/dev/null || echo 2)}"

# Debian 12 package names, one per dependency (see docs/dependencies.md).
PACKAGES=(build-essential cmake ninja-build pkg-config
          libboost-dev libboost-filesystem-dev libeigen3-dev nlohmann-json3-dev libspdlog-dev
          libvtk9-dev libgtest-dev libgmock-dev json-schema-test-suite libhypre-dev
          libopenmpi-dev openmpi-bin python3 python3-matplotlib)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "[setup] installing missing packages: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

echo "[setup] configuring and building in $BUILD_DIR (-j$JOBS)"
build_start=$SECONDS
# DOMEL_CMAKE_ARGS: further configure arguments (scripts/sanitize); the last -DCMAKE_BUILD_TYPE wins
# shellcheck disable=SC2086
cmake -S "$DOMEL_ROOT" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release ${DOMEL_CMAKE_ARGS:-} >/dev/null
cmake --build "$BUILD_DIR" -j "$JOBS"
echo "[setup] built in $((SECONDS - build_start)) s"
