#!/usr/bin/env bash
# Every C++ and shader source in git is formatted with the pinned .clang-format
# (Debian clang-format 14). Usage: check_format.sh ROOT
set -euo pipefail
root="${1:?usage: $0 ROOT}"
cd "$root"
formatter=$(command -v clang-format-14 || true)
if [ -z "$formatter" ]; then
  echo "error: clang-format-14 not found (scripts/setup.sh installs it)" >&2
  exit 1
fi
if [ -d .git ]; then
  mapfile -t files < <(git ls-files '*.h' '*.cpp' '*.hpp')
else
  mapfile -t files < <(find cpp tests examples benchmarks -name '*.h' -o -name '*.cpp')
fi
[ ${#files[@]} -eq 0 ] && exit 0
"$formatter" --dry-run --Werror "${files[@]}"
