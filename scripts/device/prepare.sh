#!/usr/bin/env bash
# Prepares what a GPU device machine needs to run binaries built here (Debian 12):
#   .gl/       the GL and Vulkan loader packages, unpacked into / there (docs/device.md);
#   .devlibs/  the shared libraries our binaries link beyond libc, libm, libdl, libpthread,
#              libgcc_s and the loaders, copied from this machine (the device's system has
#              other versions or none of them).
# Both folders are git-ignored; name them in the device call's carry list, with the binaries.
# Usage, from the repository root after a build: bash scripts/device/prepare.sh [BINARY...]
# (default: build/bin/gs-render build/bin/gs-bench).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"
binaries=("$@")
[ ${#binaries[@]} -gt 0 ] || binaries=(build/bin/gs-render build/bin/gs-bench)

# Through git rev-parse: in a worktree .git is a file and the exclude list is the main one's.
exclude=$(git rev-parse --git-path info/exclude)
for d in .gl .devlibs; do
  git check-ignore -q "$d" || echo "/$d/" >>"$exclude"
done

if ! ls .gl/*.deb >/dev/null 2>&1; then
  echo "prepare: downloading the GL and Vulkan loader packages into .gl/"
  mkdir -p .gl /tmp/amd64/partial
  o=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64)
  apt-get "${o[@]}" update >/dev/null
  (cd .gl && apt-get "${o[@]}" download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
fi

mkdir -p .devlibs
skip='^(linux-vdso|ld-linux|libc\.|libm\.|libdl\.|libpthread\.|libgcc_s\.|libvulkan\.|libGL|libEGL|libOpenGL|libGLX|libGLdispatch)'
for b in "${binaries[@]}"; do
  [ -x "$b" ] || { echo "prepare: error: $b is not built (run scripts/build.sh)" >&2; exit 1; }
  ldd "$b" | awk '$3 ~ /^\// {print $1, $3}' | while read -r name path; do
    [[ $name =~ $skip ]] || cp -L "$path" ".devlibs/$name"
  done
done
echo "prepare: .gl has $(ls .gl | wc -l) packages, .devlibs $(ls .devlibs | wc -l) libraries ($(du -sh .devlibs | cut -f1))"
