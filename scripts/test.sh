#!/usr/bin/env bash
# README command 2 (and CI): builds, then runs the whole test suite with ctest; ends with
# ctest's summary. Tests that need an X server run under Xvfb when no display is set.
# Vulkan tests run on whatever device exists (lavapipe here) with validation on.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build}"
bash "$root/scripts/build.sh"
export OPEN3D_VULKAN_VALIDATION=1
cd "$build_dir"
ctest_cmd=(ctest --output-on-failure -j"$(nproc)" --timeout 600 "$@")
if [ -z "${DISPLAY:-}" ]; then
  exec xvfb-run -a -s "-screen 0 1280x1024x24" "${ctest_cmd[@]}"
fi
exec "${ctest_cmd[@]}"
