#!/usr/bin/env bash
# README command 2 (and CI): builds, then runs the whole test suite with ctest; ends with
# ctest's summary and the reason of every skipped test. Tests that need an X server run
# under Xvfb when no display is set.
# Vulkan tests run on whatever device exists (lavapipe here) with validation on.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build}"
bash "$root/scripts/build.sh"
export OPEN3D_VULKAN_VALIDATION=1
cd "$build_dir"
# One job more than cores: many tests spend part of their time waiting on Xvfb, Filament's
# GL thread or lavapipe's worker threads, and the extra job fills the cores meanwhile
# (docs/perf/build.md). TEST_JOBS overrides it.
ctest_cmd=(ctest --output-on-failure -j"${TEST_JOBS:-$(($(nproc) + 1))}" --timeout 600 "$@")
status=0
if [ -z "${DISPLAY:-}" ]; then
  xvfb-run -a -s "-screen 0 1280x1024x24" "${ctest_cmd[@]}" || status=$?
else
  "${ctest_cmd[@]}" || status=$?
fi
# ctest shows no output of a skipped test; gtest's reason is in the log: print it.
log="$build_dir/Testing/Temporary/LastTest.log"
if [ -f "$log" ] && grep -q ": Skipped$" "$log"; then
  echo "Skipped tests and why (from $log):"
  grep -B1 -A1 ": Skipped$" "$log" | grep -v "^--$" || true
fi
exit "$status"
