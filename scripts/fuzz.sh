#!/usr/bin/env bash
# Builds the libFuzzer harnesses with clang-14 + ASan/UBSan into $BUILD_DIR (default
# build-asan, the build scripts/sanitize.sh uses: scripts/sanitized-build.sh) and runs each for
# FUZZ_SECONDS (default 60): the readers, seeded with the small
# files of ../shared/data and tests/fuzz/seeds, and the differential harness of the two
# renderers (CPU reference against Vulkan; needs a Vulkan device, lavapipe on CI). A crash or sanitizer report fails the script and
# leaves the input in $BUILD_DIR/fuzz-artifacts for a regression test.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build-asan}"
seconds="${FUZZ_SECONDS:-60}"
data="${OPEN3D_DATA_DIR:-$root/../shared/data}"
BUILD_DIR="$build_dir" bash "$root/scripts/sanitized-build.sh" fuzz_ply_reader fuzz_splat_reader \
  fuzz_cameras_json fuzz_spz_reader fuzz_compressed_ply_reader fuzz_sog_reader fuzz_gltf_reader \
  fuzz_glb_reader fuzz_ksplat_reader fuzz_splat_hierarchy_reader fuzz_splat_page_reader \
  fuzz_render_agreement
artifacts="$build_dir/fuzz-artifacts"
mkdir -p "$artifacts"
parallel="${FUZZ_JOBS:-$(nproc)}"  # harnesses at a time (each is one process)
mkdir -p "$build_dir/fuzz-logs"
fuzz_one() {  # name, seed files... (FUZZ_MAX_LEN: longest input, default 64 KiB;
              # FUZZ_LEN_CONTROL: libFuzzer's -len_control, 0 tries long inputs at once)
  local name=$1; shift
  local corpus="$build_dir/fuzz-corpus/$name"
  mkdir -p "$corpus"
  for f in "$@"; do [ -f "$f" ] && cp -n "$f" "$corpus/" || true; done
  local log="$build_dir/fuzz-logs/$name.log" status=0
  ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=${FUZZ_DETECT_LEAKS:-1}" \
    "$build_dir/bin/$name" "$corpus" -max_total_time="$seconds" -rss_limit_mb=2048 \
    -max_len="${FUZZ_MAX_LEN:-65536}" -len_control="${FUZZ_LEN_CONTROL:-100}" \
    -detect_leaks="${FUZZ_DETECT_LEAKS:-1}" \
    -artifact_prefix="$artifacts/$name-" -print_final_stats=1 >"$log" 2>&1 || status=$?
  # Printed whole when the harness ends (runs overlap). The harness's own reason (a
  # disagreement, a sanitizer report) comes before libFuzzer's stack and statistics: printed
  # first, so a CI log that keeps only the end still has it.
  {
    echo "fuzz: $name ran ${seconds}s: exit $status"
    grep -m 5 -E 'renderers disagree|ERROR: |runtime error' "$log" || true
    tail -n 12 "$log"
  } >"$log.report"
  cat "$log.report"
  return "$status"
}
pids=()
names=()
run() {  # name, seed files...: started in the background, at most $parallel at a time
  while [ "$(jobs -rp | wc -l)" -ge "$parallel" ]; do wait -n || true; done
  echo "fuzz: $1 for ${seconds}s"
  fuzz_one "$@" &
  pids+=("$!")
  names+=("$1")
}
run fuzz_ply_reader "$data/pc_short/pc_short.ply" "$data/train3/train_3points.ply" "$root"/tests/fuzz/seeds/*.ply
run fuzz_splat_reader "$data/train3/one_splat.splat"
run fuzz_cameras_json "$data/playbot/cameras.json" "$data/chair/cameras.json"
formats="$data/formats"
run fuzz_spz_reader "$formats/minimal-v3.spz" "$formats/minimal-v4.spz" "$root"/tests/fuzz/seeds/*.spz
run fuzz_compressed_ply_reader "$root"/tests/fuzz/seeds/*.compressed.ply
run fuzz_sog_reader "$root"/tests/fuzz/seeds/*.sog
run fuzz_gltf_reader "$formats/cesium_synthetic_0.gltf" "$root"/tests/fuzz/seeds/*.gltf
run fuzz_glb_reader "$root"/tests/fuzz/seeds/*.glb
run fuzz_ksplat_reader "$formats/minimal.ksplat" "$root"/tests/fuzz/seeds/*.ksplat
run fuzz_splat_hierarchy_reader "$root"/tests/fuzz/seeds/*.lod
run fuzz_splat_page_reader "$root"/tests/fuzz/seeds/*.gspages
# The harness reads at most ~130 bytes (six splats and a camera) and runs at ~5 inputs/s on
# lavapipe under ASan (~570 MB resident): without -len_control=0, libFuzzer's slowly growing
# length limit kept a 20 s run at 4-byte inputs (one splat, all else zero). Without leak
# detection, as sanitize.sh runs the tests that make a lavapipe device: lavapipe keeps 128
# bytes from its own module that LeakSanitizer reports as a leak of an unknown module (an
# empty input reproduces it, with the harness of any commit); ASan and UBSan still check.
FUZZ_DETECT_LEAKS=0 FUZZ_MAX_LEN=256 FUZZ_LEN_CONTROL=0 run fuzz_render_agreement "$root"/tests/fuzz/seeds/render_*.bin

failed=()
for i in "${!pids[@]}"; do
  wait "${pids[$i]}" || failed+=("${names[$i]}")
done
if [ ${#failed[@]} -ne 0 ]; then
  echo "fuzz: failed: ${failed[*]} (inputs in $artifacts)" >&2
  exit 1
fi
echo "fuzz: all ${#names[@]} harnesses ran ${seconds}s each without a finding"
