#!/usr/bin/env bash
# The one sanitized build of scripts/sanitize.sh and scripts/fuzz.sh: clang-14 with
# AddressSanitizer + UBSan and libFuzzer's coverage instrumentation, into $BUILD_DIR (default
# build-asan). Both scripts build their targets here, so CI compiles the libraries once for
# the sanitized tests and the fuzz harnesses instead of twice (docs/build.md).
# Usage: sanitized-build.sh TARGET... (prints build.sh's phases; log in $BUILD_DIR/build.log)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export BUILD_DIR="${BUILD_DIR:-$root/build-asan}"
export BUILD_TYPE=RelWithDebInfo
export BUILD_TARGETS="$*"
# -O1 -g1: line tables for the reports at 60% of the -O2 -g compile time (a 2-core CI
# machine spends most of the sanitizer stage compiling).
bash "$root/scripts/build.sh" -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
  -DOPEN3D_SANITIZE=ON -DOPEN3D_BUILD_FUZZERS=ON \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  -DOPEN3D_BUILD_BENCHMARKS=OFF
