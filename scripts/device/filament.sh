#!/usr/bin/env bash
# The Filament layer on the GPU device machine (issue 48, docs/filament.md "On NVIDIA"):
# Xvfb (carried, with Mesa's swrast for its GLX extension) as the X server, NVIDIA's libGLX
# for the clients' OpenGL contexts (__GLX_VENDOR_LIBRARY_NAME=nvidia), Vulkan on the GPU.
# Prepare here: bash scripts/device/prepare-x.sh; bash scripts/device/prepare.sh BINARIES.
# Two calls, the second within the machine's warm period (30 s), since .xroot (55 MB) and the
# binaries with a scene do not fit one call's 64 MB:
#   1. carry .gl and .xroot:  bash scripts/device/filament.sh OUT probe
#      (unpacks .xroot into /opt/xroot, which the warm machine keeps)
#   2. carry .gl, .devlibs, .devbin and shared/data/playbot:
#      bash scripts/device/filament.sh OUT suites|bench|all
# Everything is logged under OUT; the last lines printed are a summary.
set -uo pipefail
out=${1:?usage: bash scripts/device/filament.sh OUT probe|suites|bench|all}
mode=${2:-all}
mkdir -p "$out"
summary=$out/summary.txt
say() { echo "$*" | tee -a "$summary"; }
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
xr=/opt/xroot
for part in xvfb mesa validation; do
  if [ -f ".xroot/$part.tar.xz" ] && [ ! -e "$xr/$part.done" ]; then
    mkdir -p "$xr/$part" && tar -C "$xr/$part" -xJf ".xroot/$part.tar.xz" && touch "$xr/$part.done"
  fi
done
[ -f .xroot/gl_probe ] && cp .xroot/gl_probe "$xr/"
if [ ! -e "$xr/xvfb.done" ] || [ ! -e "$xr/mesa.done" ]; then
  say "filament.sh: /opt/xroot is not unpacked: carry .xroot (scripts/device/prepare-x.sh)"
  exit 2
fi
# Xvfb's GLX loads <dri>/swrast_dri.so from its compiled-in path and runs xkbcomp from
# /usr/bin; the device has neither. Links only, nothing of / is overwritten.
dri=/usr/lib/x86_64-linux-gnu/dri
[ -e $dri/swrast_dri.so ] || { mkdir -p $dri && ln -s $xr/mesa/dri/swrast_dri.so $dri/swrast_dri.so; }
[ -e /usr/bin/xkbcomp ] || ln -s $xr/xvfb/bin/xkbcomp /usr/bin/xkbcomp
xlibs=$xr/xvfb/lib:$xr/mesa/lib
LD_LIBRARY_PATH=$xlibs $xr/xvfb/bin/Xvfb :99 -screen 0 3840x2160x24 -nolisten tcp \
  -xkbdir $xr/xvfb/share/X11/xkb >"$out/xvfb.log" 2>&1 &
for _ in $(seq 100); do [ -S /tmp/.X11-unix/X99 ] && break; sleep 0.1; done
[ -S /tmp/.X11-unix/X99 ] || { say "Xvfb did not start:"; tail -20 "$out/xvfb.log"; exit 2; }
export DISPLAY=:99
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv,noheader | tee "$out/gpu.txt"

probe() {
  say "== gl_probe, Mesa (Xvfb's own GLX):"
  LD_LIBRARY_PATH=$xlibs LIBGL_DRIVERS_PATH=$xr/mesa/dri $xr/gl_probe 2>&1 | tee -a "$summary"
  say "== gl_probe, __GLX_VENDOR_LIBRARY_NAME=nvidia:"
  LD_LIBRARY_PATH=$xlibs __GLX_VENDOR_LIBRARY_NAME=nvidia $xr/gl_probe 2>&1 | tee -a "$summary"
}

export __GLX_VENDOR_LIBRARY_NAME=nvidia
if [ -e $xr/validation.done ]; then
  export VK_LAYER_PATH=$xr/validation
else
  export OPEN3D_VULKAN_VALIDATION=0
fi
suites() {
  export LD_LIBRARY_PATH=$PWD/.devlibs OPEN3D_DATA_DIR=$PWD/shared/data
  local name
  for name in tests_filament_rendering tests_visualizer; do
    [ -x ".devbin/$name" ] || { say "$name: not carried"; continue; }
    timeout 400 ".devbin/$name" --gtest_brief=1 >"$out/$name.log" 2>&1
    say "$name: exit $? ($(grep -c '^\[  FAILED' "$out/$name.log") failed lines)"
    grep -E "^\[  (PASSED|FAILED|SKIPPED) |host copies|zero-copy|Vulkan device" "$out/$name.log" |
      sort | uniq -c | head -20 | tee -a "$summary"
  done
}
bench() {
  export LD_LIBRARY_PATH=$PWD/.devlibs
  local d=shared/data/playbot size w h sharing backend log
  [ -x .devbin/gs-render ] || { say "gs-render: not carried"; return; }
  for size in 1920x1080 3840x2160; do
    w=${size%x*} h=${size#*x}
    # The integrated frame (splats, a lit sphere, Filament's mesh view, the depth-tested
    # composite, the offscreen read and blend), zero-copy and host copies; then Filament's own
    # frame (placeholder backend: no splats) and the splats alone (gs-bench, GPU and in flight).
    for sharing in zero-copy host-copy; do
      log=$out/render-$size-$sharing.log
      OPEN3D_SPLAT_SHARING=$sharing timeout 120 .devbin/gs-render -i $d/playbot_125k.ply \
        --cameras $d/cameras.json --view 0 --width "$w" --height "$h" --sphere --frames 100 \
        -o /tmp/filament-$size.png >"$log" 2>&1
      say "gs-render --sphere $size $sharing: exit $?"
      grep -E "^filament render|^frame time|rror" "$log" | tee -a "$summary"
    done
    log=$out/render-$size-placeholder.log
    timeout 120 .devbin/gs-render -i $d/playbot_125k.ply --cameras $d/cameras.json --view 0 \
      --width "$w" --height "$h" --sphere --frames 100 --backend placeholder \
      -o /tmp/filament-mesh-$size.png >"$log" 2>&1
    say "gs-render --sphere $size, meshes only: exit $?"
    grep -E "^frame time|rror" "$log" | tee -a "$summary"
  done
  cp /tmp/filament-1920x1080.png "$out/" 2>/dev/null
  [ -x .devbin/gs-bench ] || return
  timeout 120 .devbin/gs-bench -i $d/playbot_125k.ply --cameras $d/cameras.json --views 0 \
    --knobs default --resolution 1920x1080 --resolution 3840x2160 --repeat 50 --warm-up 2 \
    --reference-max-splats 0 >"$out/gs-bench.log" 2>&1
  say "gs-bench, splats alone: exit $?"
  grep -E "^default |in flight" "$out/gs-bench.log" | tee -a "$summary"
}
case $mode in
  probe) probe ;;
  suites) suites ;;
  bench) bench ;;
  all) probe; suites; bench ;;
  *) echo "unknown mode $mode"; exit 2 ;;
esac
nvidia-smi --query-gpu=clocks.sm --format=csv,noheader | tee -a "$out/gpu.txt"
