#!/usr/bin/env bash
# README command 1: builds what is needed and renders the built-in default scene
# (SH degree 3, anisotropic, semi-transparent splats) with a red sphere through Filament
# (meshes and splats composited with the depth test) to a PNG with gs-render.
# Any arguments are passed to gs-render instead (try: scripts/run.sh --help).
# Filament needs an X server: without a display the command runs under xvfb-run.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build}"
mkdir -p "$build_dir"
# Quiet build; on failure show what went wrong.
if ! bash "$root/scripts/build.sh" >"$build_dir/build.log" 2>&1; then
  tail -n 40 "$build_dir/build.log" >&2
  echo "run.sh: the build failed (full log: $build_dir/build.log)" >&2
  exit 1
fi
if [ $# -eq 0 ]; then
  set -- --sphere --output "$build_dir/default_scene.png" --depth-output "$build_dir/default_scene_depth.png"
fi
if [ -z "${DISPLAY:-}" ] && command -v xvfb-run >/dev/null; then
  exec xvfb-run -a -s "-screen 0 1280x1024x24" "$build_dir/bin/gs-render" "$@"
fi
exec "$build_dir/bin/gs-render" "$@"
