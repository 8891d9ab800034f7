#!/usr/bin/env bash
# Installs the Debian 12 packages the project builds and tests with.
# Idempotent: when everything is present it only runs dpkg-query (well under a second).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git python3
  libfmt-dev libeigen3-dev nlohmann-json3-dev libcli11-dev libpng-dev libstb-dev zlib1g-dev libzstd-dev libwebp-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  clang-14 clang-format-14 libclang-rt-14-dev libfuzzer-14-dev
  libvulkan-dev mesa-vulkan-drivers vulkan-tools vulkan-validationlayers
  glslang-tools glslang-dev spirv-cross libspirv-cross-c-shared-dev
  libx264-dev  # H.264 videos (gs-render --camera-path -o x.mp4)
  libopenh264-dev  # the video tests decode with it
  libfilament-dev libfilament-tools libglfw3-dev libimgui-dev
  libxrandr-dev  # glfw3native.h (the GLX context handed to Filament) includes Xrandr.h
  xvfb xauth libgl1-mesa-dri libgl-dev libegl-dev libegl-mesa0 xdotool
  python3-dev pybind11-dev python3-numpy python3-pytest  # the Python package (docs/python.md)
  python3-dask python3-distributed  # open3d_gs.distributed, rendering on a Dask cluster (docs/distributed.md)
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} Debian packages are installed"
  exit 0
fi

echo "setup: installing ${#missing[@]} missing Debian packages: ${missing[*]}"
if ! command -v apt-get >/dev/null 2>&1; then
  echo "setup: error: apt-get is not available; install these packages by hand: ${missing[*]}" >&2
  exit 1
fi
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    sudo_cmd=(sudo)
  else
    echo "setup: error: not root and no sudo; install as root: ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done"
