#!/usr/bin/env bash
# The Filament layer on the GPU device machine (issue 48; results in docs/perf/h100.md "The
# Filament-integrated frame on EGL").
# Headless by default: Filament and our OpenGL context on NVIDIA's EGL (no X server), Vulkan
# on the same GPU. With an X server (.xroot carried, see below) the GLX platform runs too:
# Xvfb with Mesa's swrast for its GLX extension, NVIDIA's libGLX for the clients' contexts
# (__GLX_VENDOR_LIBRARY_NAME=nvidia), and the viewer's suite.
# Prepare here: bash scripts/device/prepare.sh build/bin/{gs-render,gs-bench,tests_filament_rendering,tests_visualizer,tests_gaussian_splat_vulkan}
# and copy those binaries into .devbin; bash scripts/device/prepare-x.sh for .xroot.
# EGL call: carry .gl, .devlibs, .devbin, .xroot/validation.tar.xz and shared/data/playbot:
#   bash scripts/device/filament.sh OUT [probe|suites|bench|all|quick|check]
# bench takes VARIANTS (default "zero-copy zero-copy-hostwait host-copy"), SEMAPHORES (the
# OPEN3D_GL_VK_SEMAPHORES of the variants that are not -hostwait, default 1), TAG (a name for
# this run's logs, e.g. an environment variable being compared) and BASELINES=0 (skip the
# meshes-only frame and gs-bench).
# GLX: .xroot (55 MB) and the binaries with a scene do not fit one call's 64 MB: carry .gl and
# .xroot first (`... OUT probe`, unpacks into /opt/xroot, which a warm machine keeps), then
# the rest within the warm period with OPEN3D_FILAMENT_PLATFORM=glx before the command.
# Everything is logged under OUT; the last lines printed are a summary.
set -uo pipefail
out=${1:?usage: bash scripts/device/filament.sh OUT probe|suites|bench|all|quick|check}
mode=${2:-all}
mkdir -p "$out"
summary=$out/summary.txt
say() { echo "$*" | tee -a "$summary"; }
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
export __EGL_VENDOR_LIBRARY_FILENAMES=${__EGL_VENDOR_LIBRARY_FILENAMES:-/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json}
xr=/opt/xroot
for part in xvfb mesa validation; do
  if [ -f ".xroot/$part.tar.xz" ] && [ ! -e "$xr/$part.done" ]; then
    mkdir -p "$xr/$part" && tar -C "$xr/$part" -xJf ".xroot/$part.tar.xz" && touch "$xr/$part.done"
  fi
done
[ -f .xroot/gl_probe ] && cp .xroot/gl_probe "$xr/"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv,noheader | tee "$out/gpu.txt"

platform=${OPEN3D_FILAMENT_PLATFORM:-egl}
export OPEN3D_FILAMENT_PLATFORM=$platform
unset DISPLAY
xlibs=$xr/xvfb/lib:$xr/mesa/lib
if [ -e "$xr/xvfb.done" ] && [ -e "$xr/mesa.done" ]; then
  # Xvfb's GLX loads <dri>/swrast_dri.so from its compiled-in path and runs xkbcomp from
  # /usr/bin; the device has neither. Links only, nothing of / is overwritten.
  dri=/usr/lib/x86_64-linux-gnu/dri
  [ -e $dri/swrast_dri.so ] || { mkdir -p $dri && ln -s $xr/mesa/dri/swrast_dri.so $dri/swrast_dri.so; }
  [ -e /usr/bin/xkbcomp ] || ln -s $xr/xvfb/bin/xkbcomp /usr/bin/xkbcomp
  LD_LIBRARY_PATH=$xlibs $xr/xvfb/bin/Xvfb :99 -screen 0 3840x2160x24 -nolisten tcp \
    -xkbdir $xr/xvfb/share/X11/xkb >"$out/xvfb.log" 2>&1 &
  for _ in $(seq 100); do [ -S /tmp/.X11-unix/X99 ] && break; sleep 0.1; done
  if [ -S /tmp/.X11-unix/X99 ]; then
    export DISPLAY=:99 __GLX_VENDOR_LIBRARY_NAME=nvidia
  else
    say "Xvfb did not start:"; tail -20 "$out/xvfb.log"
  fi
elif [ "$platform" = glx ]; then
  say "filament.sh: GLX needs /opt/xroot: carry .xroot first (scripts/device/prepare-x.sh)"
  exit 2
fi
say "platform: $platform, DISPLAY=${DISPLAY:-unset}"

probe() {
  [ -n "${DISPLAY:-}" ] || { say "probe: no X server"; return; }
  say "== gl_probe, Mesa (Xvfb's own GLX):"
  LD_LIBRARY_PATH=$xlibs LIBGL_DRIVERS_PATH=$xr/mesa/dri __GLX_VENDOR_LIBRARY_NAME=mesa \
    $xr/gl_probe 2>&1 | tee -a "$summary"
  say "== gl_probe, __GLX_VENDOR_LIBRARY_NAME=nvidia:"
  LD_LIBRARY_PATH=$xlibs $xr/gl_probe 2>&1 | tee -a "$summary"
}

if [ -e $xr/validation.done ]; then
  # The suites run with the Khronos validation layer, as scripts/test.sh runs them here.
  export VK_LAYER_PATH=$xr/validation OPEN3D_VULKAN_VALIDATION=${OPEN3D_VULKAN_VALIDATION:-1}
else
  export OPEN3D_VULKAN_VALIDATION=0
fi
say "validation: ${OPEN3D_VULKAN_VALIDATION:-on}"
suites() {
  export LD_LIBRARY_PATH=$PWD/.devlibs OPEN3D_DATA_DIR=$PWD/shared/data
  local name
  # The Vulkan suite's interop tests: memory and semaphore export on the GPU.
  for name in ${SUITES:-tests_filament_rendering tests_visualizer tests_gaussian_splat_vulkan}; do
    [ -x ".devbin/$name" ] || { say "$name: not carried"; continue; }
    local filter='*'
    [ "$name" = tests_gaussian_splat_vulkan ] && filter='Interop.*:DeferredComposite.*'
    timeout "${SUITE_TIMEOUT:-300}" ".devbin/$name" --gtest_filter="$filter" >"$out/$name.log" 2>&1
    local rc=$?
    say "$name: exit $rc"
    # A crash or a hang names no test: the last one started is where it stopped.
    [ $rc -eq 0 ] || grep "^\[ RUN" "$out/$name.log" | tail -1 | tee -a "$summary"
    grep -E "^\[  (PASSED|FAILED|SKIPPED) |^\[==========\]|Splat images|hands the mesh|Vulkan device|rror" \
      "$out/$name.log" | sort | uniq -c | sort -rn | head -12 | cut -c1-400 | tee -a "$summary"
  done
}
bench() {
  export LD_LIBRARY_PATH=$PWD/.devlibs OPEN3D_VULKAN_VALIDATION=0
  local d=shared/data/playbot size w h variant sharing semaphores log
  [ -x .devbin/gs-render ] || { say "gs-render: not carried"; return; }
  for size in ${SIZES:-1920x1080 3840x2160}; do
    w=${size%x*} h=${size#*x}
    # The integrated frame (splats, a lit sphere, Filament's mesh view, the depth-tested
    # composite, the offscreen read and blend), zero-copy and host copies; then Filament's own
    # frame (--meshes-only: no splats) and the splats alone (gs-bench, GPU and in flight).
    # zero-copy-hostwait: zero-copy with the host waiting for GL instead of the semaphore.
    for variant in ${VARIANTS:-zero-copy zero-copy-hostwait host-copy}; do
      sharing=${variant%-hostwait}
      semaphores=${SEMAPHORES:-1}
      [ "$variant" = zero-copy-hostwait ] && semaphores=0
      log=$out/render-$size-$variant${TAG:+-$TAG}.log
      OPEN3D_SPLAT_SHARING=$sharing OPEN3D_GL_VK_SEMAPHORES=$semaphores timeout 120 \
        .devbin/gs-render -i $d/playbot_125k.ply \
        --cameras $d/cameras.json --view 0 --width "$w" --height "$h" --sphere --plane --frames 60 \
        -o /tmp/filament-$size-$variant.png >"$log" 2>&1
      say "gs-render --sphere --plane $size $variant${TAG:+ ($TAG)}: exit $?"
      grep -E "^filament render|^frame time|^presented|^GL GPU timeline|hands the mesh|rror" "$log" | cut -c1-400 | tee -a "$summary"
      # A crash's call stack (core::InstallCrashReport): place the frames with addr2line here.
      grep -A16 "fatal signal" "$log" | cut -c1-200 | tee -a "$summary"
    done
    [ "${BASELINES:-1}" = 1 ] || continue
    # Filament's own frame, its targets in imported Vulkan memory (zero-copy) and in GL's own
    # textures (host-copy): whether the imported memory slows GL's drawing.
    for sharing in zero-copy host-copy; do
      log=$out/render-$size-meshes-only-$sharing.log
      OPEN3D_SPLAT_SHARING=$sharing timeout 120 .devbin/gs-render -i $d/playbot_125k.ply \
        --cameras $d/cameras.json --view 0 --width "$w" --height "$h" --sphere --plane \
        --frames 60 --meshes-only -o /tmp/filament-mesh-$size.png >"$log" 2>&1
      say "gs-render --sphere --plane $size, meshes only, $sharing targets: exit $?"
      grep -E "^frame time|^presented|^GL GPU timeline|rror" "$log" | cut -c1-400 | tee -a "$summary"
    done
  done
  cp /tmp/filament-1920x1080-zero-copy.png "$out/" 2>/dev/null
  [ -x .devbin/gs-bench ] && [ "${BASELINES:-1}" = 1 ] || return
  timeout 120 .devbin/gs-bench -i $d/playbot_125k.ply --cameras $d/cameras.json --views 0 \
    --knobs default --resolution 1920x1080 --resolution 3840x2160 --repeat 30 --warm-up 1 \
    --reference-max-splats 0 >"$out/gs-bench.log" 2>&1
  say "gs-bench, splats alone: exit $?"
  grep -E "^default |in flight" "$out/gs-bench.log" | cut -c1-300 | tee -a "$summary"
}
case $mode in
  probe) probe ;;
  suites) suites ;;
  bench) bench ;;
  all) probe; suites; bench ;;
  quick) SUITE_TIMEOUT=90 suites; bench ;;  # a short lease: each suite stops after 90 s
  # The least that says whether the integrated frame works and what it costs, at 1080p.
  check) SUITE_TIMEOUT=100 SUITES=tests_filament_rendering suites; SIZES=1920x1080 bench ;;
  *) echo "unknown mode $mode"; exit 2 ;;
esac
nvidia-smi --query-gpu=clocks.sm --format=csv,noheader | tee -a "$out/gpu.txt"
# At most 8 files come back from a device call: the logs travel as one archive.
(cd "$out" && ls ./*.log >/dev/null 2>&1 && tar -czf logs.tar.gz ./*.log && rm -f ./*.log)
