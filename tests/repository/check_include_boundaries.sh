#!/usr/bin/env bash
# Layer boundaries (STYLE.md point 2): only a `vulkan/` folder includes <vulkan/...> and
# only a `filament/` folder includes Filament headers. Usage: check_include_boundaries.sh ROOT
set -euo pipefail
root="${1:?usage: $0 ROOT}"
cd "$root"
status=0
while IFS= read -r -d '' file; do
  case "$file" in
    */vulkan/*) ;;
    *)
      if grep -nE '^\s*#\s*include\s*[<"](vulkan/|vk_)' "$file"; then
        echo "error: $file includes Vulkan headers outside a vulkan/ folder" >&2
        status=1
      fi ;;
  esac
  case "$file" in
    */filament/*) ;;
    *)
      if grep -nE '^\s*#\s*include\s*[<"](filament/|filamat/|backend/|gltfio/|filameshio/|utils/EntityManager|math/mat)' "$file"; then
        echo "error: $file includes Filament headers outside a filament/ folder" >&2
        status=1
      fi ;;
  esac
done < <(find cpp tests examples benchmarks -type f \( -name '*.h' -o -name '*.cpp' -o -name '*.hpp' \) \
           -not -path 'tests/repository/fixtures/*' -print0 2>/dev/null)
exit $status
