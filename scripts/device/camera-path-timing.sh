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
# An MP4 needs an ffmpeg program there (the device image is not known to hold one; the script
# looks on PATH and in Python's imageio_ffmpeg). Without one it times the same run into the
# tests' stand-in ffmpeg, which reads and counts the frames (render + 8-bit readback + pipe,
# no encoding); what.txt says which was measured.
set -uo pipefail
out=${1:?usage: bash scripts/device/camera-path-timing.sh OUT_DIR}
mkdir -p "$out"
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv | tee "$out/gpu.txt"

ffmpeg=$(command -v ffmpeg || python3 -c 'import imageio_ffmpeg; print(imageio_ffmpeg.get_ffmpeg_exe())' 2>/dev/null || true)
if [[ -n $ffmpeg && -x $ffmpeg ]]; then
  bin=$(mktemp -d /tmp/ffmpeg-XXXX)
  ln -s "$ffmpeg" "$bin/ffmpeg"
  what="MP4 through $ffmpeg"
else
  # The tests' stand-in: reads every frame, writes their byte count as the "video".
  bin=$PWD/tests/apps/gs_render/fake_ffmpeg
  what="no ffmpeg on the device: frames piped into a stand-in that reads and counts them (no encoding)"
fi
echo "camera-path-timing: $what" | tee "$out/what.txt"

d=shared/data/playbot
# 24 keyframes over 10 s: 10 / 23 s apart.
run() {  # NAME OUTPUT
  local start end
  start=$(date +%s.%N)
  PATH="$bin:$PATH" LD_LIBRARY_PATH=$PWD/.devlibs timeout 60 .devbin/gs-render \
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
rm -f "$out"/*.mp4  # the videos are not needed back; their sizes are in times.txt
