#!/usr/bin/env bash
# README command 1: builds what is needed, then shows the built-in default scene (SH degree
# 3, anisotropic, semi-transparent splats) with a red sphere composited depth-aware through
# Filament: in the interactive viewer when a display is available, otherwise rendered to a
# PNG with gs-render, headless on EGL (and it says so).
# Any arguments are passed to gs-render instead (try: scripts/run.sh --help).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build}"
# Only what this script runs: gs-render, and the viewer when a display is there to show it
# (the tests and the Python package are built by scripts/test.sh and scripts/build.sh).
targets="gs-render"
if [ $# -eq 0 ] && [ -n "${DISPLAY:-}" ]; then targets="GaussianSplat"; fi
echo "run.sh: building $targets (build.sh prints each phase)"
BUILD_TARGETS="$targets" bash "$root/scripts/build.sh"
if [ $# -eq 0 ]; then
  if [ -n "${DISPLAY:-}" ]; then
    # A display: the interactive viewer on the default scene with a red sphere.
    echo "run.sh: opening the viewer on the built-in default scene"
    exec "$build_dir/bin/GaussianSplat"
  fi
  echo "run.sh: no display (DISPLAY is unset), so the default scene is rendered to a PNG" \
       "instead of opening the viewer (build/bin/GaussianSplat)."
  set -- --sphere --output "$build_dir/default_scene.png" --depth-output "$build_dir/default_scene_depth.png"
fi
echo "run.sh: rendering: gs-render $*"
# Without a display Filament runs headless on EGL (docs/filament.md).
exec "$build_dir/bin/gs-render" "$@"
