#!/usr/bin/env bash
# The radix sort's two algorithms side by side on the GPU device machine, from binaries built
# here (docs/radix-sort.md): the sort, geometry stage and frame suites with the
# one-sweep sort, then gs-bench frames with OPEN3D_RADIX_SORT=multipass and =onesweep
# alternating scene by scene, so that both see the same clocks.
# Prepare here:
#   mkdir -p .devbin && cp build/bin/{gs-bench,tests_gaussian_splat_vulkan} .devbin/ && strip .devbin/*
#   bash scripts/device/prepare.sh .devbin/gs-bench .devbin/tests_gaussian_splat_vulkan
# The call carries .gl, .devlibs, .devbin and the scene files (shared/ is a link and travels
# only path by path): playbot_125k.ply, chair.splat, biker_152k.ply and their cameras.json.
#   bash scripts/device/sort-ab.sh OUT_DIR [all | suites | bench | quick]
# (quick: the suites, then playbot_125k and its first splat only, for a short lease)
# (suites, then other work, then bench: the frames are timed only where the one-sweep suites
# passed).
# VAR and VALUES compare another switch the same way, e.g. VAR=OPEN3D_CHAINED_EMIT VALUES="0 1"
# (the geometry stage's separate scan, cut and emit passes against the chained one); the
# default is VAR=OPEN3D_RADIX_SORT VALUES="multipass onesweep".
set -uo pipefail
out=${1:?usage: bash scripts/device/sort-ab.sh OUT_DIR [all | suites | bench]}
what=${2:-all}
mkdir -p "$out"
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
export LD_LIBRARY_PATH=$PWD/.devlibs
export OPEN3D_DATA_DIR=$PWD/shared/data OPEN3D_VULKAN_VALIDATION=0 OPEN3D_TEST_REQUIRE_VULKAN=1
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv | tee "$out/gpu.txt"

if [[ $what != bench ]]; then
  echo "== suites with the one-sweep sort"
  OPEN3D_RADIX_SORT=onesweep timeout 240 .devbin/tests_gaussian_splat_vulkan \
    --gtest_filter='*RadixSort*:RealScenes/GeometryStageScenes*:SubmissionPath*:GeometryStageFeatures*:GeometryStageChainedEmit*:VulkanBackend*:LodCut*:CommandTally*:Stress*:Interop*:Deferred*' \
    --gtest_output=xml:"$out/suites.xml" >"$out/suites.log" 2>&1
  echo $? >"$out/suites.rc"
  echo "suites exit $(cat "$out/suites.rc"): $(grep -E '^\[  (PASSED|FAILED) ' "$out/suites.log" | tr '\n' ' ')"
  grep -E '^\[  FAILED  \]' "$out/suites.log" | head -20
fi
[[ $what == suites ]] && exit 0
# A hang (timeout's 124) or a failing one-sweep suite: the one-sweep frames are not timed.
if [[ $(cat "$out/suites.rc" 2>/dev/null) == 124 ]] || grep -q 'FAILED.*OneSweep' "$out/suites.log"; then
  echo "sort-ab: the one-sweep suites hung or failed here; no timing" >&2
  exit 1
fi

d=shared/data
var=${VAR:-OPEN3D_RADIX_SORT}
values=${VALUES:-multipass onesweep}
bench() {  # NAME ARGS...: one gs-bench run per value of $var
  local name=$1
  shift
  for value in $values; do
    env "$var=$value" timeout 90 .devbin/gs-bench "$@" --knobs default --repeat 50 \
      --warm-up 2 --reference-max-splats 0 --json "$out/$name-$value.json" >"$out/$name-$value.log" 2>&1
    echo "== $name $var=$value (exit $?)"
    grep -E "^default|dispatches" "$out/$name-$value.log"
  done
}
hd=(--resolution 1920x1080 --resolution 3840x2160)
bench playbot -i $d/playbot/playbot_125k.ply --cameras $d/playbot/cameras.json "${hd[@]}"
[[ $what == quick ]] && {
  bench first1 -i $d/playbot/playbot_125k.ply --cameras $d/playbot/cameras.json --first 1 "${hd[@]}"
  exit 0
}
bench chair -i $d/chair/chair.splat --cameras $d/chair/cameras.json "${hd[@]}"
bench biker -i $d/biker/biker_152k.ply --cameras $d/biker/cameras.json "${hd[@]}"
bench first1 -i $d/playbot/playbot_125k.ply --cameras $d/playbot/cameras.json --first 1 "${hd[@]}"
bench first1000 -i $d/playbot/playbot_125k.ply --cameras $d/playbot/cameras.json --first 1000 "${hd[@]}"
bench grid7 -i $d/playbot/playbot_125k.ply --cameras $d/playbot/cameras.json --grid 7 "${hd[@]}"
bench batch -i $d/playbot/playbot_125k.ply --cameras $d/playbot/cameras.json --resolution 800x800 --batch 24
nvidia-smi --query-gpu=clocks.sm --format=csv | tee -a "$out/gpu.txt"
# The comparison as one table (also printed), then the logs and JSON as one archive: at most
# 8 files come back from a device call.
command -v python3 >/dev/null && python3 scripts/device/ab_table.py "$out" $values | tee "$out/table.md"
(cd "$out" && tar -czf runs.tar.gz ./*.log ./*.json 2>/dev/null && rm -f ./*.log ./*.json)
