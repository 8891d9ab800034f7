#!/usr/bin/env bash
# Issue 52's frame-time target on the GPU device machine (docs/lod.md "A budget that holds a
# frame time"): gs-bench --lod-target-ms on a path through all 24 views of cameras.json (10
# frames from each view to the next, 231 frames after 30 warm-up frames) of playbot_125k at
# 1920x1080 (target 0.38 ms) and 3840x2160 (0.65 ms): between the hierarchy scene's floor (a
# cut of one node: the cut's passes over every node and a frame's fixed cost, 0.29 ms at
# 1080p on the H100) and every leaf; and the 7x7 grid of it (6.1M splats, one camera turned
# 20 degrees either way) at 1080p with a target of 1.5 ms (every leaf ~3.1 ms).
# Prepare here as scripts/device/camera-path-timing.sh says; the call carries .gl, .devlibs,
# .devbin and shared/data/playbot:
#   bash scripts/device/lod-target.sh OUT_DIR
set -uo pipefail
out=${1:?usage: bash scripts/device/lod-target.sh OUT_DIR}
mkdir -p "$out"
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
export LD_LIBRARY_PATH=$PWD/.devlibs
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv | tee "$out/gpu.txt"
d=shared/data/playbot
bench() {  # NAME ARGS...
  local name=$1
  shift
  timeout 240 .devbin/gs-bench -i $d/playbot_125k.ply --cameras $d/cameras.json --views all \
    --knobs default --repeat 5 --warm-up 1 --reference-max-splats 0 \
    --lod-target-frames 10 "$@" >"$out/$name.log" 2>&1
  echo "$name: exit $?" | tee -a "$out/summary.txt"
  grep -E "^default |lod target" "$out/$name.log" | tee -a "$out/summary.txt"
}
bench playbot_1080p --resolution 1920x1080 --lod-target-ms 0.38
bench playbot_4k --resolution 3840x2160 --lod-target-ms 0.65
bench grid7_1080p --grid 7 --resolution 1920x1080 --lod-target-ms 1.5
nvidia-smi --query-gpu=name,clocks.sm --format=csv,noheader | tee -a "$out/gpu.txt"
