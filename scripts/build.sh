#!/usr/bin/env bash
# Installs missing Debian packages, then configures and builds into $BUILD_DIR
# (default: build/). Extra arguments go to CMake's configure step, e.g.
#   scripts/build.sh -DOPEN3D_SANITIZE=ON      (AddressSanitizer + UBSan)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build}"
bash "$root/scripts/setup.sh"
cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" "$@" >/dev/null
cmake --build "$build_dir" -j"$(nproc)"
