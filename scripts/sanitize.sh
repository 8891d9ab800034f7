#!/usr/bin/env bash
# The CPU and lavapipe tests under AddressSanitizer + UndefinedBehaviorSanitizer (a second
# build in $BUILD_DIR, default build-asan). Run by CI after README command 2.
# The Vulkan validation layer stays off here: with it loaded LeakSanitizer reports
# allocations it cannot attribute (docs/environment-notes.md); the main test run keeps
# validation on. Extra arguments go to ctest.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build-asan}"
bash "$root/scripts/setup.sh"
# -O1 -g1: line tables for the reports at 60% of the -O2 -g compile time (a 2-core CI
# machine spends most of this script compiling: 15 s -> 9 s for VulkanBackendTest.cpp).
cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DOPEN3D_SANITIZE=ON \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  -DOPEN3D_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target tests_core tests_geometry tests_io tests_camera \
  tests_gaussian_splat tests_gaussian_splat_cpu tests_gaussian_splat_vulkan gs-render gs-convert \
  gs-bench
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
status=0
ctest --output-on-failure -j"$(nproc)" --timeout 1200 -L "^cpu$" -E "^gs_(render|bench)_cli\." "$@" ||
  status=$?
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1"
ctest --output-on-failure -j"$(nproc)" --timeout 1200 -L "^vulkan$" "$@" || status=$?
ctest --output-on-failure -j"$(nproc)" --timeout 1200 -L "^cpu$" -R "^gs_(render|bench)_cli\." "$@" ||
  status=$?
exit "$status"
