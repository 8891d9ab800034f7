#!/usr/bin/env bash
# Layer boundaries (docs/DESIGN.md "Layers"): only a `vulkan/` folder includes <vulkan/...>, only a
# `filament/` folder includes Filament headers, and only the visualizer layer
# (cpp/open3d/visualization/visualizer/, its tests) and the apps (cpp/apps/) include GLFW or
# ImGui, so windowing and UI never leak into the rendering libraries.
# Usage: check_include_boundaries.sh ROOT
set -euo pipefail
root="${1:?usage: $0 ROOT}"
cd "$root"
status=0

# check FILE FOLDER LIBRARY PATTERN: FILE outside */FOLDER/* must not include PATTERN.
check() {
  local file=$1 folder=$2 library=$3 pattern=$4
  case "$file" in */"$folder"/*) return 0 ;; esac
  if grep -nE "^\s*#\s*include\s*[<\"]($pattern)" "$file"; then
    echo "error: $file includes $library headers outside a $folder/ folder" >&2
    status=1
  fi
}

# check_paths FILE LIBRARY PATTERN PATH...: FILE outside the PATH prefixes must not include
# PATTERN.
check_paths() {
  local file=$1 library=$2 pattern=$3
  shift 3
  local prefix
  for prefix in "$@"; do
    case "$file" in "$prefix"*) return 0 ;; esac
  done
  if grep -nE "^\s*#\s*include\s*[<\"]($pattern)" "$file"; then
    echo "error: $file includes $library headers outside $*" >&2
    status=1
  fi
}

# Where GLFW and ImGui may be included: the visualizer layer, its tests and the apps.
ui_layers=(cpp/open3d/visualization/visualizer/ tests/visualization/visualizer/ cpp/apps/)
# Known exception, to be removed when the rendering layer stops creating its own GL context
# (issue 23): the Filament integration opens a hidden GLFW window for its headless GL
# context (FilamentEngine.cpp, GlFunctions.cpp, SplatTargets.cpp). GLFW only, never ImGui.
glfw_exceptions=(cpp/open3d/visualization/rendering/filament/)

while IFS= read -r -d '' file; do
  file=${file#./}
  check "$file" vulkan Vulkan 'vulkan/|vk_'
  check "$file" filament Filament \
    'filament/|filamat/|backend/|gltfio/|filameshio/|utils/EntityManager|math/mat'
  check_paths "$file" GLFW 'GLFW/' "${ui_layers[@]}" "${glfw_exceptions[@]}"
  check_paths "$file" ImGui 'imgui|filagui/' "${ui_layers[@]}"
done < <(find cpp tests examples benchmarks -type f \( -name '*.h' -o -name '*.cpp' -o -name '*.hpp' \) \
           -not -path 'tests/repository/fixtures/*' -print0 2>/dev/null)
exit $status
