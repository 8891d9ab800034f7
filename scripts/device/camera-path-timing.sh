#!/usr/bin/env bash
# Issue 53's camera-path timing on the GPU device machine (docs/camera-paths.md): a 10 s path
# through playbot_125k's 24 views at 30 fps (301 frames) at 1920x1080, rendered in batches by
# gs-render --camera-path, wall time of the whole command.
# Prepare here:
#   mkdir -p .devbin && cp build/bin/{gs-bench,gs-render,tests_gaussian_splat_vulkan} .devbin/ && strip .devbin/*
#   bash scripts/device/prepare.sh .devbin/gs-bench .devbin/gs-render .devbin/tests_gaussian_splat_vulkan
# The call carries .gl, .devlibs, .devbin, shared/data/playbot/playbot_125k.ply and
# shared/data/playbot/cameras.json:
#   bash scripts/device/camera-path-timing.sh OUT_DIR
# The MP4 is encoded by libx264 inside gs-render (t/io/H264VideoWriter.h): prepare.sh copies
# libx264.so.164 into .devlibs with the binaries' other libraries, so nothing else is needed.
# A fourth run writes a PNG sequence of the same frames (render + float readback + PNG zlib).
set -uo pipefail
out=${1:?usage: bash scripts/device/camera-path-timing.sh OUT_DIR}
mkdir -p "$out"
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv | tee "$out/gpu.txt"

nproc | sed 's/^/cpu cores: /' | tee -a "$out/gpu.txt"

d=shared/data/playbot
# 24 keyframes over 10 s: 10 / 23 s apart.
run() {  # NAME OUTPUT
  local start end
  start=$(date +%s.%N)
  LD_LIBRARY_PATH=$PWD/.devlibs timeout 120 .devbin/gs-render \
    -i $d/playbot_125k.ply --camera-path $d/cameras.json --seconds-per-keyframe 0.434782608695652 \
    --fps 30 --width 1920 --height 1080 -o "$2" >"$out/$1.log" 2>&1
  local rc=$?
  end=$(date +%s.%N)
  echo "$1: exit $rc, wall $(awk "BEGIN {print $end - $start}") s" | tee -a "$out/times.txt"
  tail -3 "$out/$1.log"
}
run warm "$out/warm.mp4"  # first run: driver shader caches, page cache
run timed "$out/path.mp4"
run timed_again "$out/path2.mp4"
ls -la "$out"/*.mp4 2>/dev/null | tee -a "$out/times.txt"
rm -f "$out/warm.mp4" "$out/path2.mp4"  # path.mp4 comes back to be looked at
mkdir -p /tmp/frames
run png_sequence /tmp/frames/f.png
ls /tmp/frames | wc -l | sed 's/^/png frames: /' | tee -a "$out/times.txt"
