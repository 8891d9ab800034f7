#!/usr/bin/env bash
# The CPU and lavapipe tests under AddressSanitizer + UndefinedBehaviorSanitizer (clang-14, a
# second build in $BUILD_DIR, default build-asan, shared with scripts/fuzz.sh:
# scripts/sanitized-build.sh). Run by CI after README command 2.
# The Vulkan validation layer stays off here: with it loaded LeakSanitizer reports
# allocations it cannot attribute (docs/environment-notes.md); the main test run keeps
# validation on. Extra arguments go to ctest.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build-asan}"
BUILD_DIR="$build_dir" bash "$root/scripts/sanitized-build.sh" tests_core tests_geometry tests_io \
  tests_camera tests_gaussian_splat tests_gaussian_splat_cpu tests_gaussian_splat_vulkan \
  gs-render gs-convert gs-bench
cd "$build_dir"
export OPEN3D_VULKAN_VALIDATION=0
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# The gs-render, gs-bench and gs-convert command-line tests run the binaries: they are
# sanitized too (gs-render and gs-bench make a lavapipe device: no leak check, below).
# Tests that create a lavapipe device run without LeakSanitizer: lavapipe leaves 128 bytes
# allocated from its own module, which the loader has unloaded by exit (the report names an
# unknown module), so LeakSanitizer can attribute nothing to our code there; AddressSanitizer
# and UBSan still check them. The CPU tests keep leak detection.
# Left to the main run (scripts/test.sh): tests whose cost is size (hundreds of MB of
# buffers), not code paths the small tests miss. Under ASan on two cores they took a third of
# this stage (docs/perf/build.md).
large='^(RoundTrip\.LargeFilesReportProgress|VulkanMemoryCheck\..*|Stress\.Resolution1920x1080)$'
status=0
ctest --output-on-failure -j"$(nproc)" --timeout 1200 -L "^cpu$" -E "^gs_(render|bench)_cli\.|$large" \
  "$@" || status=$?
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1"
ctest --output-on-failure -j"$(nproc)" --timeout 1200 -L "^vulkan$" -E "$large" "$@" || status=$?
ctest --output-on-failure -j"$(nproc)" --timeout 1200 -L "^cpu$" -R "^gs_(render|bench)_cli\." "$@" ||
  status=$?
exit "$status"
