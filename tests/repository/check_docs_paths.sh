#!/usr/bin/env bash
# The docs stay true (docs/DESIGN.md "Code rules"): every repository path written in
# backticks in docs/*.md, docs/*/*.md and README.md must exist. Usage: check_docs_paths.sh ROOT
set -euo pipefail
root="${1:?usage: $0 ROOT}"
cd "$root"
status=0
for doc in docs/*.md docs/*/*.md README.md; do
  [ -f "$doc" ] || continue
  # Backticked tokens that start with a top-level folder of the repository.
  while IFS= read -r path; do
    [ -e "$path" ] && continue
    echo "error: $doc names '$path', which does not exist" >&2
    status=1
  done < <(grep -oE '`(cpp|tests|shaders|docs|scripts|cmake|3rdparty|examples|benchmarks|\.ci)/[A-Za-z0-9_./-]*`' "$doc" \
             | tr -d '`' | sed 's/[.,:]$//' | sort -u)
done
exit $status
