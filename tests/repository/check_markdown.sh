#!/usr/bin/env bash
# Markdown that a code formatter has been run over fails: a heading whose #s are not
# followed by a space ("#Design", "##Context"), a path written with spaced slashes
# ("cpp / open3d / visualization", "docs / perf"), an arrow split into "- >". Fenced code
# blocks are skipped. The docs stay true (docs/DESIGN.md "Code rules").
# Usage: check_markdown.sh ROOT
set -euo pipefail
root="${1:?usage: $0 ROOT}"
cd "$root"
if [ -e .git ]; then
  mapfile -t files < <(git ls-files '*.md' | grep -v '^tests/repository/fixtures/')
else
  mapfile -t files < <(find . -name '*.md' -not -path './build*' | sed 's|^\./||' | sort)
fi
[ ${#files[@]} -eq 0 ] && exit 0
awk '
  FNR == 1 { fence = 0 }
  /^[ \t]*(```|~~~)/ { fence = !fence; next }
  fence { next }
  function report(why) {
    printf "error: %s:%d: %s: %s\n", FILENAME, FNR, why, $0 > "/dev/stderr"
    status = 1
  }
  /^[ \t]*#+[^# \t!]/ { report("heading without a space after the #s") }
  # A top-level folder or a folder of the source tree followed by a spaced slash, or a
  # spaced-slash chain that ends in a file name.
  /(^|[^A-Za-z0-9_])(\.\.|cpp|docs|tests|shaders|scripts|cmake|3rdparty|examples|benchmarks|open3d|visualization|rendering|gaussian_splat|repository|fixtures|perf|shared|apps)[ \t]+\/[ \t]+[A-Za-z0-9_.]/ {
    report("path with spaced slashes")
    next
  }
  /[A-Za-z0-9_]+ \/ [A-Za-z0-9_-]+\.(h|hpp|cpp|md|sh|comp|glsl|txt|cmake|py|json|ply)([^A-Za-z0-9_]|$)/ {
    report("path with spaced slashes")
    next
  }
  /(^|[^-])- >[ \t]/ { report("arrow split into \"- >\"") }
  END { exit status }
' "${files[@]}"
