#!/usr/bin/env bash
# Installs missing Debian packages, then configures and builds into $BUILD_DIR (default:
# build/). Extra arguments go to CMake's configure step, e.g.
#   scripts/build.sh -DOPEN3D_SANITIZE=ON      (AddressSanitizer + UBSan)
# BUILD_TARGETS: the targets to build (default: all), e.g. BUILD_TARGETS="gs-render".
# CC / CXX: the compilers of a new build folder (default: clang-14 and clang++-14).
# The compiler's output goes to $BUILD_DIR/build.log; the terminal gets a line per phase and
# one per tenth of the build, and the end of the log when the build fails.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build}"
read -r -a targets <<<"${BUILD_TARGETS:-all}"
start=$SECONDS
bash "$root/scripts/setup.sh"
mkdir -p "$build_dir"
# clang-14 (installed by setup.sh) compiles this tree in about two thirds of GCC 12's CPU time
# (docs/perf/build.md). CC / CXX choose another compiler; CMake reads them at the first configure
# of a build folder only, so an existing folder keeps its compiler.
if [ -z "${CC:-}" ] && [ -z "${CXX:-}" ] && command -v clang++-14 >/dev/null 2>&1; then
  export CC=clang-14 CXX=clang++-14
fi
log="$build_dir/build.log"
: >"$log"
echo "build: configuring $build_dir (${BUILD_TYPE:-Release})"
if ! cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" "$@" \
  >>"$log" 2>&1; then
  tail -n 40 "$log" >&2
  echo "build: configuring failed (full log: $log)" >&2
  exit 1
fi
compiler=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build_dir/CMakeCache.txt")
echo "build: compiling ${targets[*]} with ${compiler##*/} on $(nproc) cores (compiler output: $log)"
next=10
status=0
# Ninja prints "[done/total] what" per step when its output is not a terminal.
while IFS= read -r line; do
  printf '%s\n' "$line" >>"$log"
  if [[ $line =~ ^\[([0-9]+)/([0-9]+)\] ]]; then
    done_steps=${BASH_REMATCH[1]}
    total=${BASH_REMATCH[2]}
    percent=$((100 * done_steps / total))
    if ((percent >= next)); then
      echo "build: $done_steps/$total steps (${percent}%, $((SECONDS - start)) s)"
      next=$((percent / 10 * 10 + 10))
    fi
  fi
done < <(cmake --build "$build_dir" -j"$(nproc)" --target "${targets[@]}" 2>&1 || echo "build-status: $?")
if grep -q "^build-status: " "$log"; then status=1; fi
if [ "$status" -ne 0 ]; then
  grep -v "^build-status: " "$log" | tail -n 40 >&2
  echo "build: the build failed (full log: $log)" >&2
  exit 1
fi
echo "build: done in $((SECONDS - start)) s"
