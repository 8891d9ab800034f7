#!/usr/bin/env bash
# Prepares .xroot/, what the GPU device machine needs to run the Filament layer (GLX only in
# Filament 1.9.25, docs/filament.md) with NVIDIA's OpenGL: the device has no X server.
#   xvfb.tar.xz        Xvfb, xkbcomp, the XKB data and their libraries (from this machine)
#   mesa.tar.xz        Mesa's swrast_dri.so and its libraries (LLVM): Xvfb's GLX extension
#                      loads it; the clients' contexts come from NVIDIA's libGLX through
#                      __GLX_VENDOR_LIBRARY_NAME=nvidia
#   validation.tar.xz  the Khronos validation layer, so the suites run there with validation
#   gl_probe           scripts/device/gl_probe.cpp: the GL driver's vendor, extensions, UUIDs
# .xroot is git-ignored and about 55 MB: carry it alone in the first device call
# (scripts/device/filament.sh unpacks it into /opt/xroot, kept while the machine stays warm).
# Usage, from the repository root: bash scripts/device/prepare-x.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"
exclude=$(git rev-parse --git-path info/exclude)
git check-ignore -q .xroot || echo "/.xroot/" >>"$exclude"
mkdir -p .xroot
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
multiarch=/usr/lib/x86_64-linux-gnu
# Libraries beyond the C library and the GL loaders (the device unpacks .gl's loaders).
copy_libs() {  # DEST BINARY...
  local dest=$1
  shift
  mkdir -p "$dest"
  ldd "$@" | awk '$3 ~ /^\// {print $3}' | sort -u |
    grep -v -E '/(libc|libm|libdl|libpthread|librt|ld-linux[^/]*|libGL|libGLX|libGLdispatch|libEGL|libOpenGL)\.' |
    xargs -I{} cp -L {} "$dest/"
}
pack() {  # NAME DIR
  echo "prepare-x: packing $1 ($(du -sh "$2" | cut -f1))"
  tar -C "$2" -cf - . | xz -9 -T2 >".xroot/$1.tar.xz"
}

g++ -O1 -o .xroot/gl_probe scripts/device/gl_probe.cpp -lglfw
if [ ! -f .xroot/xvfb.tar.xz ]; then
  x=$stage/xvfb
  mkdir -p "$x/bin" "$x/share/X11"
  cp -L /usr/bin/Xvfb /usr/bin/xkbcomp "$x/bin/"
  cp -r /usr/share/X11/xkb "$x/share/X11/"
  copy_libs "$x/lib" /usr/bin/Xvfb /usr/bin/xkbcomp .xroot/gl_probe
  pack xvfb "$x"
fi
if [ ! -f .xroot/mesa.tar.xz ]; then
  m=$stage/mesa
  mkdir -p "$m/dri"
  cp -L $multiarch/dri/swrast_dri.so "$m/dri/"
  copy_libs "$m/lib" $multiarch/dri/swrast_dri.so
  pack mesa "$m"
fi
if [ ! -f .xroot/validation.tar.xz ]; then
  v=$stage/validation
  mkdir -p "$v"
  cp -L $multiarch/libVkLayer_khronos_validation.so "$v/"
  # The manifest names the library by its absolute path there.
  sed 's#"library_path": *"[^"]*"#"library_path": "/opt/xroot/validation/libVkLayer_khronos_validation.so"#' \
    /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json >"$v/VkLayer_khronos_validation.json"
  pack validation "$v"
fi
echo "prepare-x: .xroot holds $(du -sh .xroot | cut -f1)"
