#!/usr/bin/env bash
# Layer boundaries (docs/DESIGN.md "Layers"): only a `vulkan/` folder includes <vulkan/...> and
# only a `filament/` folder includes Filament headers. Usage: check_include_boundaries.sh ROOT
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

while IFS= read -r -d '' file; do
  check "$file" vulkan Vulkan 'vulkan/|vk_'
  check "$file" filament Filament \
    'filament/|filamat/|backend/|gltfio/|filameshio/|utils/EntityManager|math/mat'
done < <(find cpp tests examples benchmarks -type f \( -name '*.h' -o -name '*.cpp' -o -name '*.hpp' \) \
           -not -path 'tests/repository/fixtures/*' -print0 2>/dev/null)
exit $status
